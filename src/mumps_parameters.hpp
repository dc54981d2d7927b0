// The MUMPS settings (MumpsOptions) and the parameters a scene gives them in
// Solver/Stratimikos/Linear Solver Types/MUMPS and .../Preconditioner Types/MUMPS: kept in a
// light header so that the scene reader checks them and `capstan params` prints them without
// Thyra or Tpetra (src/mumps_solve_factory.cpp hands them to the solver).
#pragma once

#include <Teuchos_ParameterList.hpp>
#include <Teuchos_RCP.hpp>

#include <stdexcept>
#include <string>

namespace capstan {

struct MumpsOptions {
  // Fill-reducing ordering of the (sequential) analysis. Debian's MUMPS lacks METIS (ICNTL(7) = 5
  // falls back to AMF): Metis is METIS_NodeND's ordering, made here. Auto: METIS and QAMD analysed,
  // fewer estimated flops kept (docs/performance.md, "Defaults and why").
  enum class Ordering { Auto, Metis, Pord, Amd, Amf, Qamd };
  Ordering ordering = Ordering::Auto;
  // ICNTL(14): percentage by which the working space may grow over the
  // analysis' estimate (delayed pivots); < 0 keeps MUMPS' default. On
  // INFOG(1) = -8 or -9 it is raised and the factorisation retried once.
  int workspaceIncreasePercent = -1;
  // MUMPS' own printing (ICNTL(1..4)); silent by default.
  bool verbose = false;
  // Row and column scaling before each factorisation (ICNTL(8) = 77) or none (0). Off: faster, the
  // same iterations and answers, threshold pivoting still guarding the pivots (docs/performance.md,
  // "Defaults and why"; tests/integration/direct_solvers.py).
  bool scaling = false;
  // Matrices with fewer rows are factored on rank 0 alone, larger ones by all ranks: below 2,000
  // neither wins clearly (docs/performance.md, "Defaults and why"). 0: always all ranks. Scene:
  // Solver/Stratimikos/Linear Solver Types/MUMPS/Host Only Below.
  long hostOnlyBelow = 2000;
  // MUMPS sees only the entries nonzero since the graph was built, and the diagonal; a new nonzero
  // redoes the analysis. Entities coupling nodes only where they act (steady friction) stay out of
  // the factors (docs/performance.md, "Defaults and why"). Off: the graph's pattern.
  bool nonzeroPattern = true;
  // With nonzeroPattern: a row's entries in one node's 3 columns join the pattern together, so an
  // undeformed regular mesh's chance zeros do not redo the analysis later. Set with symmetricPart;
  // with friction the factors grow (docs/performance.md, "Defaults and why").
  bool nonzeroNodeBlocks = false;
  // The factorisation's arithmetic. Single (smumps): half the factors' memory
  // and traffic, a factorisation accurate to about 1e-7 x the condition
  // number: a preconditioner for GMRES, which restores double precision, not
  // a solve of its own (the direct solve's factory refuses it).
  enum class Precision { Double, Single };
  Precision precision = Precision::Double;
  // Factor the symmetric part (A + A^T) / 2 in LDL^T (SYM = 2): about half the factors, for a GMRES
  // preconditioner only (the direct solve refuses it); frictionless tangents are nearly symmetric
  // (docs/performance.md, "Defaults and why"). Other ranks' transposes are exchanged each time.
  bool symmetricPart = false;
};

// "Ordering" (Auto | Metis | Pord | AMD | AMF | QAMD), "Verbose", "Scaling", "Host Only Below",
// "Precision", "Nonzero Node Blocks", "Symmetric Part", "Nonzero Pattern", with their defaults.
Teuchos::RCP<const Teuchos::ParameterList> validMumpsOptions();

// A parameter of those lists that is unknown, of another type or out of range.
struct MumpsParameterError : std::invalid_argument {
  MumpsParameterError(const std::string& parameter, const std::string& what)
      : std::invalid_argument(what), name(parameter) {}
  std::string name;  // the parameter's name in the list
};

// The options a list gives (the defaults where it is silent); throws MumpsParameterError.
MumpsOptions mumpsOptionsFrom(const Teuchos::ParameterList& list);

}  // namespace capstan
