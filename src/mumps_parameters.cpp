#include "mumps_parameters.hpp"

#include <utility>
#include <vector>

namespace capstan {

namespace {

const std::vector<std::pair<const char*, MumpsOptions::Ordering>> kOrderings = {
    {"Auto", MumpsOptions::Ordering::Auto},   {"Metis", MumpsOptions::Ordering::Metis},
    {"Pord", MumpsOptions::Ordering::Pord},
    {"AMD", MumpsOptions::Ordering::Amd},     {"AMF", MumpsOptions::Ordering::Amf},
    {"QAMD", MumpsOptions::Ordering::Qamd}};

}  // namespace

Teuchos::RCP<const Teuchos::ParameterList> validMumpsOptions() {
  static Teuchos::RCP<Teuchos::ParameterList> valid;
  if (valid.is_null()) {
    valid = Teuchos::parameterList("MUMPS");
    valid->set("Ordering", std::string("Auto"),
               "Fill-reducing ordering: Auto (Metis and QAMD analysed, the fewer estimated flops kept) | Metis "
               "(METIS_NodeND, computed by capstan) | Pord | AMD | AMF | QAMD "
               "(src/direct_solver.hpp has the measurements)");
    valid->set("Verbose", false, "MUMPS' own printing");
    valid->set("Scaling", false, "Row and column scaling before each factorisation (MUMPS' automatic choice)");
    valid->set("Host Only Below", 2000,
               "Matrices with fewer rows are factored on rank 0 alone, larger ones by every rank; 0: always every "
               "rank (src/direct_solver.hpp has the measurements)");
    valid->set("Precision", std::string("Double"),
               "Double | Single: the factorisation's arithmetic; Single (half the memory) only as GMRES' "
               "preconditioner (Solver/Preconditioner = LU), whose iterations restore double precision");
    valid->set("Nonzero Node Blocks", false,
               "With Nonzero Pattern: a row's entries in one node's columns join the pattern together once any is "
               "nonzero; capstan sets it without friction");
    valid->set("Symmetric Part", false,
               "Factor (A + A^T) / 2 as a symmetric matrix (LDL^T): half the work, for GMRES' preconditioner "
               "(Solver/Preconditioner = LU) where A is nearly symmetric; capstan sets it without friction");
    valid->set("Nonzero Pattern", true,
               "MUMPS sees the entries nonzero so far (and the diagonal), the analysis redone when one more turns "
               "nonzero; false: the matrix graph's whole pattern");
  }
  return valid;
}

MumpsOptions mumpsOptionsFrom(const Teuchos::ParameterList& list) {
  const auto valid = validMumpsOptions();
  for (const auto& entry : list) {
    const std::string& name = entry.first;
    if (!valid->isParameter(name)) {
      std::string names;  // the valid list's own, in its order
      for (const auto& known : *valid) names += (names.empty() ? "" : ", ") + known.first;
      throw MumpsParameterError(name, "unknown (capstan's MUMPS takes " + names + ")");
    }
    const auto& want = valid->getEntry(name).getAny(false);
    const auto& got = entry.second.getAny(false);
    if (entry.second.isList() || got.type() != want.type())
      throw MumpsParameterError(name, "expected type " + want.typeName() + ", got " +
                                          (entry.second.isList() ? std::string("a sublist") : got.typeName()));
  }
  const auto get = [&](const char* name, auto fallback) {
    return list.isParameter(name) ? list.get<decltype(fallback)>(name) : valid->get<decltype(fallback)>(name);
  };
  MumpsOptions o;
  const auto ordering = get("Ordering", std::string());
  bool known = false;
  for (const auto& [name, value] : kOrderings)
    if (ordering == name) o.ordering = value, known = true;
  if (!known) throw MumpsParameterError("Ordering", "'" + ordering + "' is not Auto, Metis, Pord, AMD, AMF or QAMD");
  o.verbose = get("Verbose", false);
  o.scaling = get("Scaling", false);
  o.nonzeroPattern = get("Nonzero Pattern", false);
  o.symmetricPart = get("Symmetric Part", false);
  o.nonzeroNodeBlocks = get("Nonzero Node Blocks", false);
  const auto precision = get("Precision", std::string());
  if (precision != "Double" && precision != "Single")
    throw MumpsParameterError("Precision", "'" + precision + "' is not Double or Single");
  o.precision = precision == "Single" ? MumpsOptions::Precision::Single : MumpsOptions::Precision::Double;
  const int hostOnlyBelow = get("Host Only Below", 0);
  if (hostOnlyBelow < 0) throw MumpsParameterError("Host Only Below", std::to_string(hostOnlyBelow) + " is negative");
  o.hostOnlyBelow = hostOnlyBelow;
  return o;
}

}  // namespace capstan
