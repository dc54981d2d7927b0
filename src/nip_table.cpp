#include "nip_table.hpp"

#include <mpi.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <vector>

#include "collective.hpp"
#include "csv.hpp"
#include "model.hpp"
#include "outputs.hpp"
#include "vec3.hpp"

namespace capstan {

NipTable::NipTable(const Model& model, std::filesystem::path file) : m_(model), file_(std::move(file)) {
  text_ = std::string(kHeader) + "\n";
}

void NipTable::open(int lastKept, const std::filesystem::path& earlier) {
  if (!m_.rank0) return;
  std::ifstream in(earlier.empty() ? file_ : earlier);
  std::string line;
  if (lastKept >= 0 && std::getline(in, line))
    while (std::getline(in, line))
      if (std::atoi(line.c_str()) <= lastKept) text_ += line + "\n";
  writeAtomically(file_, text_);
}

namespace {

// The line of centres' direction, from the capstan's axis across it towards
// the body: towards the roller's axis (an annulus), or on a box along the
// inward normals of the faces the capstan touches (G1's capstan pressing on
// ymax: -y, so s = 0 under the axis wherever the capstan has moved).
std::array<double, 3> lineOfCentres(const MeshSpec& mesh, const CapstanSpec& capstan, const std::array<double, 3>& roller,
                                    const std::array<double, 3>& a, const std::array<double, 3>& b) {
  std::array<double, 3> n0{0, 0, 0};
  if (mesh.type == MeshSpec::Type::Box) {
    const auto names = mesh.faceNames();  // xmin xmax ymin ymax zmin zmax
    for (const auto& face : capstan.contactFaces)
      for (size_t k = 0; k < names.size(); ++k)
        if (face == names[k]) n0[k / 2] += k % 2 == 0 ? 1.0 : -1.0;
  }
  n0 = sub(n0, scale(b, dot(n0, b)));
  if (!(norm(n0) > 1e-12)) {  // an annulus, or box faces whose normals cancel: towards the roller's axis
    n0 = sub(roller, a);
    n0 = sub(n0, scale(b, dot(n0, b)));
  }
  return scale(n0, 1 / norm(n0));
}

}  // namespace

std::string NipTable::rows(int step) const {
  const auto& assembly = *m_.assembly;
  // The roller's axis: the inner face's rigid core where it has one, else the
  // annulus axis (a box: its centre).
  const auto& mesh = m_.scene.mesh;
  std::array<double, 3> roller = mesh.center;
  if (mesh.type == MeshSpec::Type::Box)
    for (int i = 0; i < 3; ++i) roller[i] = 0.5 * (mesh.min[i] + mesh.max[i]);
  for (const auto& core : assembly.rigidCores())
    for (int i = 0; i < 3; ++i) roller[i] = core.axisPoint[i] + core.translation[i];
  std::ostringstream out;
  out.precision(9);
  const auto& contacts = assembly.contacts();
  for (size_t c = 0; c < contacts.size(); ++c) {
    const ContactEffect& contact = *contacts[c];
    const FrictionEffect* friction = assembly.frictions()[c];
    const auto cp = contact.pointsOnHost();
    FrictionEffect::Points::HostMirror fp;
    if (friction) fp = friction->pointsOnHost();
    const auto cyl = contact.cylinder();
    const std::array<double, 3> b{cyl.b[0], cyl.b[1], cyl.b[2]}, a{cyl.a[0], cyl.a[1], cyl.a[2]};
    const double sense = contact.capstan().angularVelocity >= 0 ? 1.0 : -1.0;
    const std::array<double, 3> n0 = lineOfCentres(m_.scene.mesh, contact.capstan(), roller, a, b);
    const int nq = kernels::facePointCount(contact.rule());
    const double smoothing = contact.settings().smoothing;
    for (size_t f = 0; f < cp.extent(0); ++f)
      for (int q = 0; q < nq; ++q) {
        const double pressure = cp(f, q, ContactEffect::kPressure);
        // With a smoothed contact law points just outside the nip keep a tiny pressure.
        if (!(pressure > 0.5 * smoothing) || !(pressure > 0)) continue;
        const std::array<double, 3> x{cp(f, q, ContactEffect::kX), cp(f, q, ContactEffect::kX + 1),
                                      cp(f, q, ContactEffect::kX + 2)};
        const std::array<double, 3> e{cp(f, q, ContactEffect::kE), cp(f, q, ContactEffect::kE + 1),
                                      cp(f, q, ContactEffect::kE + 2)};
        const double phi = std::atan2(dot(cross(n0, e), b), dot(n0, e));
        const std::array<double, 3> motion = scale(cross(b, e), sense);  // the capstan surface's direction
        double shear = 0, slipRate = 0;
        const char* state = "slip";  // frictionless: the body slides freely
        if (friction) {
          const std::array<double, 3> t{fp(f, q, FrictionEffect::kTraction), fp(f, q, FrictionEffect::kTraction + 1),
                                        fp(f, q, FrictionEffect::kTraction + 2)};
          shear = dot(t, motion);
          // The slip is along -t (the traction drags the body along the capstan's slide over it).
          const double mag = norm(t), slip = fp(f, q, FrictionEffect::kSlip) * friction->slipRateScale();
          slipRate = mag > 0 ? -slip * shear / mag : 0.0;
          state = int(fp(f, q, FrictionEffect::kState)) == 1 ? "stick" : "slip";
        }
        out << step << ',' << csvCell(contact.capstan().name) << ',' << sense * contact.radius() * phi << ','
            << dot(sub(x, a), b) << ',' << pressure << ',' << shear << ',' << slipRate << ',' << state << '\n';
      }
  }
  return out.str();
}

void NipTable::add(int step) {
  const std::string mine = rows(step);
  MPI_Comm comm = rawComm(m_.comm);
  const int ranks = m_.comm->getSize();
  int length = int(mine.size());
  std::vector<int> lengths(ranks), offsets(ranks, 0);
  MPI_Gather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, 0, comm);
  std::string all;
  if (m_.rank0) {
    for (int r = 1; r < ranks; ++r) offsets[r] = offsets[r - 1] + lengths[r - 1];
    all.resize(size_t(offsets[ranks - 1] + lengths[ranks - 1]));
  }
  MPI_Gatherv(mine.data(), length, MPI_CHAR, all.data(), lengths.data(), offsets.data(), MPI_CHAR, 0, comm);
  if (!m_.rank0) return;
  text_ += all;
  writeAtomically(file_, text_);
}

}  // namespace capstan
