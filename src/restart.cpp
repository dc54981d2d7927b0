#include "restart.hpp"

#include <Teuchos_CommHelpers.hpp>

#include <chrono>
#include <fstream>
#include <map>

#include "collective.hpp"
#include "errors.hpp"
#include "parameters.hpp"

namespace capstan {

namespace fs = std::filesystem;

namespace {

std::vector<double> hostValues(const Kokkos::View<double*>& v) {
  auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), v);
  return std::vector<double>(h.data(), h.data() + h.size());
}

// Node ids of each entity of effect e (perEntity of them): the keys that put each saved value back.
// Dofs past the mesh's nodes (a rigid core's: steady friction's omega) get -1 - their place after
// them, the same in every run of the scene on as many ranks.
std::vector<long long> entityKeys(const Mesh& mesh, const Effect& e, int& perEntity) {
  auto dofs = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), e.local().dofs);
  perEntity = int(dofs.extent(1) / 3);
  const long long nodes = (long long)mesh.nodeGids.size();
  std::vector<long long> keys(dofs.extent(0) * perEntity);
  for (size_t i = 0; i < dofs.extent(0); ++i)
    for (int a = 0; a < perEntity; ++a) {
      const long long block = dofs(i, 3 * a) / 3;
      keys[i * perEntity + a] = block < nodes ? mesh.nodeGids[block] : -1 - (block - nodes);
    }
  return keys;
}

std::string checkpointBytes(const Model& model, const Timings& timings, const std::vector<StepRecord>& steps,
                            const std::vector<SolverSwitch>& switches, int step, double time,
                            const Predictors::Memory& predictors) {
  const auto& scene = model.scene;
  const auto& mesh = model.mesh;
  checkpoint::Writer w;
  w.put(std::string(checkpoint::kMagic));
  w.put<int>(model.comm->getSize()), w.put<int>(model.comm->getRank());
  w.put<int>(step), w.put<double>(time), w.put<double>(scene.stepSize);
  w.put(scene.mesh.min), w.put(scene.mesh.max), w.put(scene.mesh.cells);
  w.put(scene.mesh.outerCellRatio), w.put(scene.mesh.fineSector), w.put(std::string(scene.analysis.name()));
  // Displacement of the owned nodes, by node id.
  std::vector<long long> gids(mesh.nodeGids.begin(), mesh.nodeGids.begin() + mesh.numOwnedNodes);
  auto ud = model.u->getData();
  w.put(gids);
  w.put(std::vector<double>(ud.begin(), ud.begin() + 3 * mesh.numOwnedNodes));
  w.put(std::vector<double>(ud.begin() + 3 * mesh.numOwnedNodes, ud.end()));  // rigid cores (rank 0)
  // Every effect's multipliers and history, by its entities' node ids.
  const auto& effects = model.effects();
  w.put<int>(int(effects.size()));
  for (const auto& e : effects) {
    int perEntity = 0;
    const auto keys = entityKeys(mesh, *e, perEntity);
    w.put(e->name()), w.put<int>(perEntity), w.put(keys);
    w.put(hostValues(e->multipliers()));
    w.put(hostValues(e->history()));
  }
  // The predictors' base state, in u's layout (the node ids above).
  w.put(predictors.u), w.put(predictors.rotations), w.put<double>(predictors.t);
  // The saddle-point step taken up where Auto's Anderson loop failed (LoadStepper::advance).
  w.put<int>(model.pressureStep ? 1 : 0);
  if (model.pressureStep) w.put(model.pressureStep->carried());
  // Rank 0: the step records, and what the summary adds up over the runs.
  if (model.rank0) {
    w.put<int>(int(steps.size()));
    for (const auto& r : steps) checkpoint::put(w, r);
    w.put(timings.total), w.put(timings.assembly), w.put(timings.linearSolve), w.put(timings.output);
    w.put(timings.preconditionerSetup);
    w.put(timings.directAnalyses), w.put(timings.directFactorizations), w.put(timings.directSolves);
    for (const auto& e : timings.effects) w.put<long>(e.launches), w.put<double>(e.seconds);
    w.put<int>(int(switches.size()));
    for (const auto& s : switches) w.put<int>(s.step), w.put(s.what);
  }
  return w.bytes();
}

}  // namespace

void writeCheckpoint(const Model& model, Outputs& outputs, const std::vector<StepRecord>& steps,
                     const std::vector<SolverSwitch>& switches, int step, double time,
                     const Predictors::Memory& predictors) {
  const auto t = std::chrono::steady_clock::now();
  const Comm& comm = *model.comm;
  const fs::path root = outputs.directory() / "checkpoint";
  const std::string name = checkpoint::stepName(step);
  const fs::path done = root / name, tmp = root / (name + ".tmp");
  std::string error;
  if (model.rank0) {
    try {
      fs::remove_all(tmp);
      fs::create_directories(tmp);
    } catch (const std::exception& e) {
      error = std::string("checkpoint: ") + e.what();
    }
  }
  agreeRuntime(comm, error);
  try {
    writeAtomically(tmp / checkpoint::rankFile(comm.getRank()),
                    checkpointBytes(model, outputs.timings(), steps, switches, step, time, predictors));
  } catch (const std::exception& e) {
    error = std::string("checkpoint: ") + e.what();
  }
  agreeRuntime(comm, error);
  // Every rank's file is there: the rename publishes the checkpoint at once,
  // then the older ones go (a restart takes the newest complete one).
  if (model.rank0) {
    try {
      fs::remove_all(done);
      fs::rename(tmp, done);
      for (const auto& entry : fs::directory_iterator(root))
        if (entry.path() != done) fs::remove_all(entry.path());
    } catch (const std::exception& e) {
      error = std::string("checkpoint: ") + e.what();
    }
  }
  agreeRuntime(comm, error);
  outputs.addOutputSeconds(std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count());
}

void removeCheckpoints(const fs::path& outputDir, const fs::path& keep) {
  std::error_code ec;
  for (fs::directory_iterator it(outputDir / "checkpoint", ec), end; !ec && it != end; it.increment(ec))
    if (keep.empty() || !fs::equivalent(it->path(), keep, ec)) fs::remove_all(it->path(), ec);
}

std::string Restart::where() const { return scene_.file + ": --restart " + dir_ + ": "; }

Restart::~Restart() = default;

Restart::Restart(const Scene& scene, const Comm& comm, const std::string& dir)
    : scene_(scene), comm_(comm), dir_(dir) {
  const bool rank0 = comm.getRank() == 0;
  // Rank 0 picks the checkpoint, so every rank reads the same one.
  std::string found, error;
  std::string rank0Bytes;  // rank 0's file, read once: for the rank count here, for the values below
  int files = 0;
  if (rank0) {
    const fs::path latest = checkpoint::latest(fs::path(dir) / "checkpoint");
    if (latest.empty()) {
      error = where() + "no checkpoint in '" + (fs::path(dir) / "checkpoint").string() +
              "' (an earlier run of the scene with Output/Checkpoint Every > 0 writes them)";
    } else {
      found = latest.string();
      while (fs::exists(latest / checkpoint::rankFile(files))) ++files;
      // The rank count its first file was written with: fewer files than that
      // is a damaged checkpoint, not one of fewer ranks.
      try {
        std::ifstream in(latest / checkpoint::rankFile(0), std::ios::binary);
        if (in) rank0Bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
        checkpoint::Reader rd(rank0Bytes);
        if (rd.getString() == checkpoint::kMagic) {
          const int written = rd.get<int>();
          if (written != files)
            error = where() + "the checkpoint '" + found + "' is incomplete: written on " + std::to_string(written) +
                    " rank(s), it holds " + std::to_string(files) + " rank file(s)";
        }
      } catch (const std::exception&) {  // damaged: said below, file by file
      }
    }
  }
  agreeInput(comm, error);
  found = broadcastString(comm, found);
  Teuchos::broadcast(comm, 0, &files);
  if (files != comm.getSize())
    throw InputError(where() + "the checkpoint '" + found + "' was written on " + std::to_string(files) +
                     " rank(s); restart it on as many (mpiexec -n " + std::to_string(files) + ")");
  checkpointDir_ = found;
  file_ = checkpointDir_ / checkpoint::rankFile(comm.getRank());
  try {
    std::string bytes = std::move(rank0Bytes);
    if (bytes.empty()) {
      std::ifstream in(file_, std::ios::binary);
      if (!in) throw std::runtime_error("cannot read it");
      bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    in_ = std::make_unique<checkpoint::Reader>(std::move(bytes));
    auto& rd = *in_;
    if (const std::string magic = rd.getString(); magic != checkpoint::kMagic)
      throw std::runtime_error(magic.rfind("capstan checkpoint", 0) == 0
                                   ? "written by another version of capstan ('" + magic + "'; this one reads '" +
                                         checkpoint::kMagic + "'): run the scene again"
                                   : std::string("not a capstan checkpoint"));
    const int ranks = rd.get<int>(), rank = rd.get<int>();
    if (ranks != comm.getSize() || rank != comm.getRank())
      throw std::runtime_error("written by rank " + std::to_string(rank) + " of " + std::to_string(ranks));
    step_ = rd.get<int>();
    time_ = rd.get<double>();
    const double dt = rd.get<double>();
    const auto min = rd.get<std::array<double, 3>>(), max = rd.get<std::array<double, 3>>();
    const auto cells = rd.get<std::array<int, 3>>();
    const auto ratio = rd.get<double>();
    const auto sector = rd.get<std::array<double, 3>>();
    const std::string analysis = rd.getString();
    auto text = [&](const auto& a) {
      return "{" + shortest(a[0]) + ", " + shortest(a[1]) + ", " + shortest(a[2]) + "}";
    };
    if (cells != scene.mesh.cells)
      error = "parameter 'Mesh/Cells': the scene has " + text(scene.mesh.cells) + ", the checkpoint's mesh " +
              text(cells) + " (a different mesh size)";
    else if (min != scene.mesh.min || max != scene.mesh.max)
      error = std::string(scene.mesh.type == MeshSpec::Type::Box
                              ? "parameter 'Mesh/Min', 'Mesh/Max'"
                              : "parameter 'Mesh/Axis Point', 'Mesh/Inner Radius', 'Mesh/Outer Radius' or 'Mesh/Length'") +
              ": the scene's mesh spans " + text(scene.mesh.min) + " to " + text(scene.mesh.max) +
              ", the checkpoint's " + text(min) + " to " + text(max);
    else if (ratio != scene.mesh.outerCellRatio || sector != scene.mesh.fineSector)
      error = "parameter 'Mesh/Outer Cell Ratio' or 'Mesh/Fine Sector': the scene has " +
              shortest(scene.mesh.outerCellRatio) + " and " + text(scene.mesh.fineSector) + ", the checkpoint " +
              shortest(ratio) + " and " + text(sector) + " (its nodes sit elsewhere)";
    else if (analysis != scene.analysis.name())
      error = "parameter 'Analysis/Type': the scene has '" + std::string(scene.analysis.name()) +
              "', the checkpoint's run '" + analysis + "'";
    else if (dt != scene.stepSize)
      error = "parameter 'Time/Step Size': the scene has " + shortest(scene.stepSize) + ", the checkpoint " +
              shortest(dt);
    else if (step_ > scene.steps)
      error = "parameter 'Time/Steps': the scene has " + std::to_string(scene.steps) +
              " steps, the checkpoint is of step " + std::to_string(step_);
  } catch (const std::exception& e) {
    error = file_.string() + ": " + e.what();
  }
  agreeInput(comm, error.empty() ? "" : where() + error);
}

void Restart::restore(Model& model, std::vector<StepRecord>& steps, std::vector<SolverSwitch>& switches,
                      Timings& earlier) {
  const auto& mesh = model.mesh;
  std::string error;
  bool pressureStep = false;
  std::array<double, 2> carried{};
  try {
    auto& in = *in_;
    // Displacement: every owned node's value, found by node id.
    const auto gids = in.getVector<long long>();
    const auto u = in.getVector<double>();
    const auto cores = in.getVector<double>();
    if (gids.size() != mesh.numOwnedNodes || u.size() != 3 * gids.size())
      throw std::runtime_error("holds " + std::to_string(gids.size()) + " nodes, this rank owns " +
                               std::to_string(mesh.numOwnedNodes) + " (another mesh, or another Mesh/Partition)");
    std::map<long long, size_t> owned;
    for (size_t n = 0; n < mesh.numOwnedNodes; ++n) owned[mesh.nodeGids[n]] = n;
    auto ud = model.u->getDataNonConst();
    for (size_t i = 0; i < gids.size(); ++i) {
      const auto it = owned.find(gids[i]);
      if (it == owned.end()) throw std::runtime_error("node " + std::to_string(gids[i]) + " is not owned here");
      for (int c = 0; c < 3; ++c) ud[3 * it->second + c] = u[3 * i + c];
    }
    if (cores.size() != ud.size() - 3 * mesh.numOwnedNodes)
      throw std::runtime_error("holds " + std::to_string(cores.size()) + " rigid-core values, the scene has " +
                               std::to_string(ud.size() - 3 * mesh.numOwnedNodes) + " here");
    for (size_t j = 0; j < cores.size(); ++j) ud[3 * mesh.numOwnedNodes + j] = cores[j];
    // Effects: the same ones, each value put back on its entity by node ids.
    const auto& effects = model.effects();
    std::string have, want;
    for (const auto& e : effects) want += (want.empty() ? "" : ", ") + e->name();
    const int count = in.get<int>();
    struct Saved {
      int perEntity;
      std::vector<long long> keys;
      std::vector<double> multipliers, history;
    };
    std::vector<Saved> saved;
    for (int i = 0; i < count; ++i) {
      const std::string name = in.getString();
      have += (have.empty() ? "" : ", ") + name;
      Saved sv;
      sv.perEntity = in.get<int>();
      sv.keys = in.getVector<long long>();
      sv.multipliers = in.getVector<double>();
      sv.history = in.getVector<double>();
      saved.push_back(std::move(sv));
    }
    if (have != want)
      throw std::runtime_error("parameter 'Supports', 'Capstans' or a capstan's 'Friction/Law': the checkpoint holds "
                               "the effects [" + have + "], the scene runs [" + want + "]");
    for (size_t i = 0; i < effects.size(); ++i) {
      auto& e = *effects[i];
      const auto& sv = saved[i];
      int perEntity = 0;
      const auto keys = entityKeys(mesh, e, perEntity);
      const size_t entities = perEntity ? keys.size() / perEntity : 0;
      if (perEntity != sv.perEntity || keys.size() != sv.keys.size())
        throw std::runtime_error("parameter 'Analysis/Type' or a capstan's 'Friction/Law': the checkpoint's run had "
                                 "another (its " + e.name() + " has " +
                                 std::to_string(sv.keys.size() / std::max(sv.perEntity, 1)) + " entities of " +
                                 std::to_string(sv.perEntity) + " nodes, the scene's " + std::to_string(entities) +
                                 " of " + std::to_string(perEntity) + ")");
      std::map<std::vector<long long>, size_t> index;
      for (size_t k = 0; k < entities; ++k)
        index[std::vector<long long>(keys.begin() + k * perEntity, keys.begin() + (k + 1) * perEntity)] = k;
      auto put = [&](Kokkos::View<double*> view, const std::vector<double>& values, const char* what) {
        if (values.size() != view.size())
          throw std::runtime_error(e.name() + ": " + std::to_string(values.size()) + " " + what +
                                   ", the scene has " + std::to_string(view.size()));
        if (view.size() == 0) return;
        const size_t per = view.size() / entities;
        auto h = Kokkos::create_mirror_view(view);
        for (size_t k = 0; k < entities; ++k) {
          const auto it = index.find(
              std::vector<long long>(sv.keys.begin() + k * perEntity, sv.keys.begin() + (k + 1) * perEntity));
          if (it == index.end()) throw std::runtime_error(e.name() + ": an entity the scene does not have");
          for (size_t j = 0; j < per; ++j) h(it->second * per + j) = values[k * per + j];
        }
        Kokkos::deep_copy(view, h);
      };
      put(e.multipliers(), sv.multipliers, "multipliers");
      put(e.history(), sv.history, "history values");
    }
    // The predictors' base state: u's layout, its node ids checked above.
    const auto previous = in.getVector<double>();
    predictors_.rotations = in.getVector<double>();
    predictors_.t = in.get<double>();
    if (!previous.empty() && previous.size() != size_t(ud.size()))
      throw std::runtime_error("holds " + std::to_string(previous.size()) + " predictor values, u has " +
                               std::to_string(ud.size()));
    predictors_.u.assign(previous.size(), 0.0);
    for (size_t i = 0; i < gids.size() && !previous.empty(); ++i)
      for (int c = 0; c < 3; ++c) predictors_.u[3 * owned.at(gids[i]) + c] = previous[3 * i + c];
    for (size_t j = 3 * gids.size(); j < previous.size(); ++j) predictors_.u[j] = previous[j];
    pressureStep = in.get<int>() == 1;
    if (pressureStep) carried = in.get<std::array<double, 2>>();
    if (model.rank0) {
      const int n = in.get<int>();
      for (int i = 0; i < n; ++i) steps.push_back(checkpoint::get(in));
      earlier.total = in.get<double>(), earlier.assembly = in.get<double>();
      earlier.linearSolve = in.get<double>(), earlier.output = in.get<double>();
      earlier.preconditionerSetup = in.get<double>();
      earlier.directAnalyses = in.get<long>(), earlier.directFactorizations = in.get<long>();
      earlier.directSolves = in.get<long>();
      for (const auto& e : effects) {
        Timings::Effect t{e->name()};
        t.launches = in.get<long>();
        t.seconds = in.get<double>();
        earlier.effects.push_back(t);
      }
      switches.resize(size_t(in.get<int>()));
      for (auto& s : switches) s.step = in.get<int>(), s.what = in.getString();
    }
    if (!in.atEnd()) throw std::runtime_error("damaged (data after the end)");
  } catch (const std::exception& e) {
    error = where() + file_.string() + ": " + e.what();
  }
  agreeInput(comm_, error);
  if (pressureStep && !model.pressureStep) model.buildPressureStep();
  if (pressureStep) model.pressureStep->recall(carried);
  // fields.h5 is continued: the earlier run's must be there to append to.
  int found = 1;
  if (model.rank0 && scene_.writeFields) found = fs::exists(fs::path(dir_) / "fields.h5") ? 1 : 0;
  Teuchos::broadcast(comm_, 0, &found);
  if (!found)
    throw InputError(where() + "no fields.h5 there to continue (the earlier run had Output/Write Fields = false?)");
}

void Restart::continueFields(const Model& model, const fs::path& outputDir) const {
  if (!scene_.writeFields) return;
  std::string error;
  if (model.rank0) {
    std::error_code ec;
    const fs::path from = fs::path(dir_) / "fields.h5", to = outputDir / "fields.h5";
    if (!fs::equivalent(from, to, ec)) fs::copy_file(from, to, fs::copy_options::overwrite_existing, ec);
    if (ec) error = "cannot copy " + from.string() + " to " + to.string() + ": " + ec.message();
  }
  agreeRuntime(comm_, error);
}

}  // namespace capstan
