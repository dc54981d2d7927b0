#include "outputs.hpp"

#include <Teuchos_CommHelpers.hpp>
#include <Teuchos_XMLParameterListHelpers.hpp>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <unistd.h>

#include <fstream>
#include <sstream>

#include "collective.hpp"
#include "direct_solver.hpp"
#include "errors.hpp"
#include "json.hpp"
#include "step_figures.hpp"
#include "stopwatch.hpp"

namespace capstan {

namespace fs = std::filesystem;

namespace {

// Per rank: peak resident memory (Linux reports ru_maxrss in KiB), memory in
// transparent huge pages now, and page faults so far (src/heap_tunables.hpp),
// gathered on every rank: {peak MiB, huge-page MiB, faults} per rank.
std::array<std::vector<double>, 3> memoryFigures(const Comm& comm) {
  struct rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  double mine[3] = {double(usage.ru_maxrss) / 1024.0, 0, double(usage.ru_minflt)};
  {
    std::ifstream smaps("/proc/self/smaps_rollup");
    std::string key;
    double kib;
    while (smaps >> key)
      if (key == "AnonHugePages:" && smaps >> kib) mine[1] = kib / 1024.0;
  }
  const int ranks = comm.getSize();
  std::vector<double> all(3 * ranks);
  Teuchos::gatherAll(comm, 3, mine, 3 * ranks, all.data());
  std::array<std::vector<double>, 3> out;
  for (int f = 0; f < 3; ++f)
    for (int r = 0; r < ranks; ++r) out[f].push_back(all[3 * r + f]);
  return out;
}

std::string vec(const std::array<double, 3>& v) { return json::array({v[0], v[1], v[2]}); }

}  // namespace

void writeAtomically(const fs::path& path, const std::string& text) {
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
  }
  fs::rename(tmp, path);
}

Outputs::Outputs(Model& model, Log& log, Clock::time_point start) : m_(model), log_(log), t0_(start) {}
Outputs::~Outputs() {
  if (lock_ < 0) return;
  std::error_code ec;
  fs::remove(dir_ / ".capstan-lock", ec);  // still held: no run can have taken it meanwhile
  close(lock_);
}

namespace {
// Takes `dir`'s lock: the descriptor, or -1 with `why` set. A second run into
// the same directory would truncate the first one's fields.h5 (HDF5 opens it
// before it finds the file locked) and interleave their nip.csv rows.
int lockDirectory(const fs::path& dir, std::string& why) {
  const fs::path path = dir / ".capstan-lock";
  const int fd = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) {
    why = "cannot create " + path.string();
    return -1;
  }
  if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
    char pid[32] = {};
    const ssize_t n = pread(fd, pid, sizeof pid - 1, 0);
    std::string holder(pid, n > 0 ? size_t(n) : 0);
    while (!holder.empty() && (holder.back() == '\n' || holder.back() == ' ')) holder.pop_back();
    why = "another capstan run is writing there" + (holder.empty() ? std::string() : " (process " + holder + ")") +
          ": wait for it to end, or choose another directory";
    close(fd);
    return -1;
  }
  const std::string pid = std::to_string(getpid()) + "\n";
  if (ftruncate(fd, 0) != 0 || pwrite(fd, pid.data(), pid.size(), 0) < 0) {
    // The pid only names the holder in another run's message; the lock holds without it.
  }
  return fd;
}
}  // namespace

void Outputs::checkDirectory() {
  dir_ = m_.scene.outputDirectory;
  int dirOk = 1;
  std::string dirError;
  if (m_.rank0) {
    std::error_code ec;
    fs::create_directories(dir_, ec);
    const fs::path probe = dir_ / ".capstan-write-test";
    std::ofstream test(probe);
    if (ec || !test) {
      dirOk = 0;
      dirError = ec ? ec.message() : "not writable";
    } else {
      test.close();
      fs::remove(probe);
      lock_ = lockDirectory(dir_, dirError);
      dirOk = lock_ >= 0;
    }
  }
  Teuchos::broadcast(*m_.comm, 0, &dirOk);
  if (!dirOk)
    throw InputError(m_.scene.file + ": parameter 'Output/Directory': cannot write to '" + dir_.string() + "'" +
                     (dirError.empty() ? "" : ": " + dirError));
}

void Outputs::writeScene() {
  if (!m_.rank0) return;
  std::ostringstream xml;
  Teuchos::writeParameterListToXmlOStream(printableScene(m_.scene), xml);
  writeAtomically(dir_ / "scene.xml", xml.str());
}

FieldLayout Outputs::fieldLayout() const {
  const auto& mesh = m_.mesh;
  const auto& assembly = *m_.assembly;
  FieldLayout layout;
  layout.comm = rawComm(m_.comm);
  long long nodes = (long long)mesh.numOwnedNodes, elems = (long long)mesh.numElements();
  MPI_Exscan(&nodes, &layout.nodeOffset, 1, MPI_LONG_LONG, MPI_SUM, layout.comm);
  MPI_Exscan(&elems, &layout.elemOffset, 1, MPI_LONG_LONG, MPI_SUM, layout.comm);
  if (m_.rank0) layout.nodeOffset = layout.elemOffset = 0;
  layout.nodesOwned = nodes;
  layout.elemsOwned = elems;
  layout.nodesGlobal = mesh.numGlobalNodes;
  layout.elemsGlobal = mesh.numGlobalElements;
  // File index of every overlapped node: owners tell the ranks that share it.
  Tpetra::Vector<> fileId(mesh.ownedNodeMap), fileIdOverlap(mesh.overlapNodeMap);
  {
    auto d = fileId.getDataNonConst();
    for (size_t n = 0; n < mesh.numOwnedNodes; ++n) d[n] = double(layout.nodeOffset + (long long)n);
  }
  fileIdOverlap.doImport(fileId, Tpetra::Import<>(mesh.ownedNodeMap, mesh.overlapNodeMap), Tpetra::INSERT);
  auto ids = fileIdOverlap.getData();
  for (int n : mesh.connectivity) layout.hexConnectivity.push_back((long long)ids[n]);
  // Contact-face grid: the union of the capstans' candidate faces.
  long long faces = (long long)(assembly.contactFaceNodes().size() / 4);
  MPI_Exscan(&faces, &layout.faceOffset, 1, MPI_LONG_LONG, MPI_SUM, layout.comm);
  if (m_.rank0) layout.faceOffset = 0;
  layout.facesOwned = faces;
  layout.facesGlobal = m_.numContactFaces;
  for (int n : assembly.contactFaceNodes()) layout.quadConnectivity.push_back((long long)ids[n]);
  return layout;
}

void Outputs::openFields(const std::string& restartDir, int lastKept) {
  if (!m_.scene.writeFields) return;
  const FieldLayout layout = fieldLayout();
  if (lastKept < 0) {
    writer_ = std::make_unique<FieldWriter>(dir_.string(), layout);
    return;
  }
  try {
    writer_ = std::make_unique<FieldWriter>(dir_.string(), layout, FieldWriter::Append{lastKept});
  } catch (const std::exception& e) {
    throw InputError(m_.scene.file + ": --restart " + restartDir + ": cannot continue fields.h5: " + e.what());
  }
}

void Outputs::writeFields(int step, double time) {
  if (!writer_) return;
  const auto t = Clock::now();
  const auto& mesh = m_.mesh;
  const auto& assembly = *m_.assembly;
  const size_t nn = mesh.numOwnedNodes, ne = mesh.numElements();
  auto ud = m_.u->getData();
  std::vector<double> coords(3 * nn);
  Field disp{"displacement", 3, std::vector<double>(3 * nn)};
  for (size_t n = 0; n < nn; ++n)
    for (int i = 0; i < 3; ++i) {
      disp.values[3 * n + i] = ud[3 * n + i];
      coords[3 * n + i] = mesh.X[3 * n + i] + ud[3 * n + i];
    }
  const auto [hs, hm, hp] = elementFields(m_);
  Field p{"pressure", 1, std::vector<double>(ne)}, vm{"von_mises", 1, std::vector<double>(ne)};
  Field sig{"stress", 6, std::vector<double>(6 * ne)};
  for (size_t e = 0; e < ne; ++e) {
    p.values[e] = hp(e);
    vm.values[e] = hm(e);
    for (int k = 0; k < 6; ++k) sig.values[6 * e + k] = hs(e, k);
  }
  // Contact faces: pressure and traction summed over the capstans, the largest gap.
  const size_t nf = assembly.contactFaceNodes().size() / 4;
  Field cp{"contact_pressure", 1, std::vector<double>(nf, 0.0)};
  Field gap{"gap", 1, std::vector<double>(nf, -1e300)};
  Field ct{"contact_traction", 3, std::vector<double>(3 * nf, 0.0)};
  const auto& contacts = assembly.contacts();
  for (size_t c = 0; c < contacts.size(); ++c) {
    std::vector<double> pc, gc, tc;
    contacts[c]->faceFields(pc, gc, tc);
    const auto& index = assembly.contactFacesOf(c);
    for (size_t f = 0; f < index.size(); ++f) {
      cp.values[index[f]] += pc[f];
      gap.values[index[f]] = std::max(gap.values[index[f]], gc[f]);
      for (int i = 0; i < 3; ++i) ct.values[3 * index[f] + i] += tc[3 * f + i];
    }
  }
  // Friction: traction summed over the capstans, stick and slip point counts.
  Field ft{"friction_traction", 3, std::vector<double>(3 * nf, 0.0)};
  Field stick{"stick_points", 1, std::vector<double>(nf, 0.0)};
  Field slip{"slip_points", 1, std::vector<double>(nf, 0.0)};
  Field rate{"slip_rate", 1, std::vector<double>(nf, 0.0)};
  bool anyFriction = false;
  for (size_t c = 0; c < contacts.size(); ++c) {
    const auto* friction = assembly.frictions()[c];
    if (!friction) continue;
    anyFriction = true;
    std::vector<double> tc, sc, lc, rc;
    friction->faceFields(tc, sc, lc, rc);
    const auto& index = assembly.contactFacesOf(c);
    for (size_t f = 0; f < index.size(); ++f) {
      for (int i = 0; i < 3; ++i) ft.values[3 * index[f] + i] += tc[3 * f + i];
      stick.values[index[f]] += sc[f];
      slip.values[index[f]] += lc[f];
      rate.values[index[f]] += rc[f];
    }
  }
  std::vector<Field> faceFields;
  if (m_.numContactFaces > 0) faceFields = {cp, gap, ct};
  if (anyFriction) faceFields.insert(faceFields.end(), {ft, stick, slip, rate});
  writer_->writeStep(step, time, coords, {disp}, {p, vm, sig}, faceFields);
  outputSeconds_ += since(t);
}

void Outputs::openNip(int lastKept, const std::string& restartDir) {
  nip_ = std::make_unique<NipTable>(m_, dir_ / "nip.csv");
  nip_->open(lastKept, restartDir.empty() ? fs::path() : fs::path(restartDir) / "nip.csv");
}

void Outputs::writeNip(int step) {
  const auto t = Clock::now();
  nip_->add(step);
  outputSeconds_ += since(t);
}

void Outputs::writeHistory(const std::vector<StepRecord>& steps) {
  if (!m_.rank0) return;
  // The columns: those of the run's records, or of an empty record with the
  // scene's supports and capstans when no step converged.
  StepRecord layout;
  if (!steps.empty()) {
    layout = steps.front();
  } else {
    for (const auto& s : m_.scene.supports) layout.supports.push_back({s.name});
    for (const auto& c : m_.scene.capstans) layout.capstans.push_back({c.name});
  }
  std::string out = csvHeader(layout) + "\n";
  for (const auto& r : steps) out += csvRow(r) + "\n";
  writeAtomically(dir_ / "history.csv", out);
}

Timings Outputs::timings() const {
  Timings t;
  t.total = since(t0_) + earlier.total;
  t.assembly = m_.assembly->assemblySeconds() + earlier.assembly;
  t.linearSolve = m_.linearSolveSeconds() + earlier.linearSolve;
  t.output = outputSeconds_ + earlier.output;
  t.preconditionerSetup = m_.newton->preconditionerSeconds() + earlier.preconditionerSetup;
  const auto direct = MumpsSolver::processCounts();
  t.directAnalyses = direct.analyses + earlier.directAnalyses;
  t.directFactorizations = direct.factorizations + earlier.directFactorizations;
  t.directSolves = direct.solves + earlier.directSolves;
  for (const auto& e : m_.effects()) {
    Timings::Effect sum{e->name(), e->launches(), e->seconds()};
    for (const auto& before : earlier.effects)
      if (before.name == e->name()) sum.launches += before.launches, sum.seconds += before.seconds;
    t.effects.push_back(sum);
  }
  return t;
}

void Outputs::writeSummary(const std::vector<StepRecord>& steps, const std::vector<SolverSwitch>& switches,
                           bool converged, const std::string& failure) {
  const StateFigures s = stateFigures(m_);
  const auto [peakMiB, hugeMiB, faults] = memoryFigures(*m_.comm);
  if (!m_.rank0) return;
  using json::Object;
  auto range = [](const StateFigures::Range& r) {
    return Object().add("min", json::number(r.min)).add("max", json::number(r.max)).str();
  };
  std::string stepList = "[";
  for (size_t i = 0; i < steps.size(); ++i) stepList += (i ? ",\n    " : "\n    ") + toJson(steps[i]);
  stepList += "\n  ]";
  std::vector<std::string> switchList;
  for (const auto& w : switches)
    switchList.push_back(Object().add("step", json::number(w.step)).add("what", json::string(w.what)).str());
  const char* comp[6] = {"xx", "yy", "zz", "xy", "yz", "xz"};
  Object stress, faces;
  for (int k = 0; k < 6; ++k) stress.add(comp[k], range(s.stress[k]));
  for (const auto& f : s.faceMeans) faces.add(f.first, vec(f.second));
  Object fin;
  fin.add("von_mises", range(s.vonMises)).add("stress", stress.str())
      .add("pressure", range(s.pressure))
      .add("max_abs_volume_change", json::number(s.volumeChange))
      .add("max_displacement", vec(s.maxDisplacement))
      .add("node_displacement_mean", faces.str());
  const Timings t = timings();
  Object effects;
  for (const auto& e : t.effects)
    effects.add(e.name, Object().add("launches", json::number(e.launches)).add("seconds", json::number(e.seconds)).str());
  Object timing;
  timing.add("total", json::number(t.total))
      .add("assembly", json::number(t.assembly))
      .add("linear_solve", json::number(t.linearSolve))
      .add("output", json::number(t.output))
      .add("preconditioner_setup", json::number(t.preconditionerSetup))
      .add("direct_solver", Object()
                                .add("analyses", json::number(t.directAnalyses))
                                .add("factorizations", json::number(t.directFactorizations))
                                .add("solves", json::number(t.directSolves))
                                .str());
  Object memory;
  memory.add("peak_rss_mib", json::array(peakMiB))
      .add("peak_rss_mib_max", json::number(*std::max_element(peakMiB.begin(), peakMiB.end())))
      .add("huge_pages_mib", json::array(hugeMiB))
      .add("page_faults", json::array(faults));
  const auto& mesh = m_.mesh;
  Object meshObject;
  meshObject.add("nodes", json::number(long(mesh.numGlobalNodes)))
      .add("elements", json::number(long(mesh.numGlobalElements)))
      .add("dofs", json::number(long(3 * mesh.numGlobalNodes)))
      .add("contact_faces", json::number(m_.numContactFaces))
      .add("partition", json::string(partitionName(mesh.partition)))
      .add("cut_faces", json::number(long(mesh.numCutFaces)));
  Object top;
  top.add("title", json::string(m_.scene.title)).add("scene", json::string(m_.scene.file))
      .add("version", json::string(CAPSTAN_VERSION))
      .add("ranks", json::number(m_.comm->getSize()))
      .add("analysis", json::string(m_.scene.analysis.name()))  // interface.md, "Steady rolling"
      .add("converged", converged ? "true" : "false")
      .add("failure", converged ? "null" : json::string(failure))
      .add("solver_switches", json::list(switchList))
      .add("mesh", meshObject.str()).add("steps", stepList).add("final", fin.str())
      .add("timing", timing.str()).add("memory", memory.str()).add("effects", effects.str());
  writeAtomically(dir_ / "summary.json", top.str() + "\n");
}

}  // namespace capstan
