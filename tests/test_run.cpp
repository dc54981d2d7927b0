// The parts of a run, each reached on its own: the step record's writers
// (checkpoint, JSON, CSV, progress) agree field for field; the log writes
// only the topics that are on; the load-step controller with the
// augmentation loop solves a homogeneous stretch exactly; a failed
// increment's state comes back as it was; Open MPI's start-up settings keep
// the user's; the monolithic pass policy. Run on 1 and 2 ranks.
#include <Tpetra_Core.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "augmentation.hpp"
#include "checkpoint.hpp"
#include "effect_state.hpp"
#include "load_stepper.hpp"
#include "log.hpp"
#include "model.hpp"
#include "mpi_startup.hpp"
#include "step_figures.hpp"
#include "step_record.hpp"

using namespace capstan;

namespace {

StepRecord sampleRecord() {
  StepRecord r;
  r.step = 2, r.time = 2.0, r.newton = 7, r.linear = 31, r.cutbacks = 1, r.augmentations = 3, r.pressureStep = 9;
  r.residual = 1.25e-11, r.wall = 0.5, r.volumeChange = 3e-11;
  CapstanRecord plain{"left", {1, 2, 3}, 0.1, 1e-9, 4.5, 0.25, 0.75, 12};
  CapstanRecord rubbing{"right", {-1, 0.5, 0}, -0.2, 2e-9, 5.5, 0.3, 0.8, 16, true, 10, 6, 0.7, 1.4, 0.98};
  r.capstans = {plain, rubbing};
  SupportRecord base{"base", {0, -2, 0}};
  SupportRecord core{"core", {0.5, 1.5, 0}, true, 0.125, 0.2, 0.1, {0, -0.01, 0}, true, 0.99};
  r.supports = {base, core};
  return r;
}

std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  for (std::string c; std::getline(s, c, ',');) out.push_back(c);
  return out;
}

// A 2 x 1 x 1 block on symmetry rollers, pulled along x to lambda = 1.5 in two steps.
Scene stretchScene() {
  const std::string xml = R"XML(<ParameterList name="Scene">
    <ParameterList name="Mesh">
      <Parameter name="Max" type="Array(double)" value="{2, 1, 1}"/>
      <Parameter name="Cells" type="Array(int)" value="{4, 2, 2}"/>
    </ParameterList>
    <ParameterList name="Supports">
      <ParameterList name="xsym"><Parameter name="Face" type="string" value="xmin"/>
        <Parameter name="Type" type="string" value="Roller"/><Parameter name="Components" type="string" value="x"/></ParameterList>
      <ParameterList name="ysym"><Parameter name="Face" type="string" value="ymin"/>
        <Parameter name="Type" type="string" value="Roller"/><Parameter name="Components" type="string" value="y"/></ParameterList>
      <ParameterList name="zsym"><Parameter name="Face" type="string" value="zmin"/>
        <Parameter name="Type" type="string" value="Roller"/><Parameter name="Components" type="string" value="z"/></ParameterList>
      <ParameterList name="pull"><Parameter name="Face" type="string" value="xmax"/>
        <Parameter name="Type" type="string" value="Displacement"/><Parameter name="Components" type="string" value="x"/>
        <Parameter name="Velocity" type="Array(double)" value="{0.5, 0, 0}"/></ParameterList>
    </ParameterList>
    <ParameterList name="Time"><Parameter name="Steps" type="int" value="2"/></ParameterList>
  </ParameterList>)XML";
  return parseScene(xml, "stretch.xml", {}, "");
}

}  // namespace

TEST(StepRecord, CheckpointRoundTripKeepsEveryField) {
  const StepRecord a = sampleRecord();
  checkpoint::Writer w;
  checkpoint::put(w, a);
  checkpoint::Reader in(w.bytes());
  const StepRecord b = checkpoint::get(in);
  EXPECT_TRUE(in.atEnd());
  EXPECT_EQ(toJson(a), toJson(b));
  EXPECT_EQ(csvRow(a), csvRow(b));
  EXPECT_EQ(b.capstans[1].maxFrictionRatio, 0.98);
  EXPECT_EQ(b.supports[1].speedRatio, 0.99);
  EXPECT_EQ(b.supports[0].core, false);
}

TEST(StepRecord, WritersShowTheSameFields) {
  const StepRecord r = sampleRecord();
  const std::string json = toJson(r);
  EXPECT_NE(json.find("\"newton_iterations\": 7"), std::string::npos) << json;
  EXPECT_NE(json.find("\"speed_ratio\": 0.98999999999999999"), std::string::npos) << json;
  EXPECT_NE(json.find("\"left\": {\"force\": [1, 2, 3]"), std::string::npos) << json;
  EXPECT_NE(json.find("\"friction\": null"), std::string::npos) << json;  // the left capstan
  EXPECT_NE(json.find("\"max_traction_ratio\": 0.97999999999999998"), std::string::npos) << json;
  EXPECT_EQ(json.find("has_speed_ratio"), std::string::npos) << "flags are not figures: " << json;
  EXPECT_EQ(json.find("\"core\": true"), std::string::npos) << "flags are not figures: " << json;
  // history.csv: one cell per header column, names <item>_<field>, forces _fx.
  const auto header = cells(csvHeader(r)), row = cells(csvRow(r));
  ASSERT_EQ(header.size(), row.size());
  for (const char* column : {"step", "residual_norm", "left_fx", "right_friction_traction_integral",
                             "core_speed_ratio", "core_translation_y", "base_fz", "wall_seconds"})
    EXPECT_NE(std::find(header.begin(), header.end(), column), header.end()) << column;
  const size_t k = std::find(header.begin(), header.end(), "core_torque") - header.begin();
  EXPECT_EQ(row[k], "0.125");
  // Progress: the step line, then a line for the core (the only item with shown fields).
  const auto lines = progressLines(r, 5, 12.5);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], "step 2/5  t=2  newton=7  linear=31  |R|=1.250e-11  dV=3.0e-11  max_penetration=2.000e-09  12.50s");
  EXPECT_EQ(lines[1], "    core:  torque=0.125  rotation=0.2  omega=0.1  speed_ratio=0.990000");
}

TEST(Log, WritesOnlyTheTopicsThatAreOn) {
  const auto comm = Tpetra::getDefaultComm();
  const auto dir = std::filesystem::temp_directory_path() / ("capstan-test-log-" + std::to_string(comm->getRank()));
  std::filesystem::create_directories(dir);
  {
    Log log(true, true, {"newton"});
    log.open(dir, false);
    log.setStep(3);
    log.event("newton", "text", json::Object().add("event", json::string("newton")).add("residuals", json::array({1, 0.5})));
    log.event("other", "text", json::Object().add("event", json::string("ignored")));
    EXPECT_TRUE(log.on("newton"));
    EXPECT_FALSE(log.on("other"));
  }
  std::ifstream in(dir / "log.jsonl");
  std::string line, all;
  int lines = 0;
  while (std::getline(in, line)) ++lines, all += line;
  EXPECT_EQ(lines, 1);
  EXPECT_EQ(all, "{\"topic\": \"newton\", \"step\": 3, \"event\": \"newton\", \"residuals\": [1, 0.5]}");
  std::filesystem::remove_all(dir);
  // No topic: no file.
  Log quiet(true, true, {});
  quiet.open(dir, false);
  EXPECT_FALSE(std::filesystem::exists(dir / "log.jsonl"));
}

// The load-step controller, predictors and augmentation loop together, outside
// a run: a homogeneous stretch, whose answer is exact on any mesh.
TEST(LoadStepper, SolvesAHomogeneousStretchExactly) {
  const Scene scene = stretchScene();
  Model model(scene, Tpetra::getDefaultComm());
  Log log(model.rank0, true, {});
  LoadStepper stepper(model, log, false, 0.0);
  std::vector<StepRecord> steps;
  for (int step = 1; step <= 2; ++step) {
    StepRecord rec;
    rec.step = step, rec.time = step;
    std::string failure;
    ASSERT_TRUE(stepper.advance(rec, failure)) << failure;
    EXPECT_EQ(rec.cutbacks, 0);
    EXPECT_GT(rec.newton, 0);
    EXPECT_LE(rec.volumeChange, 1e-10);
    measureStep(model, steps, rec);
    steps.push_back(rec);
    for (const auto& e : model.effects()) e->commit(model.assembly->positions());
  }
  EXPECT_DOUBLE_EQ(stepper.time(), 2.0);
  // lambda = (2 + 2 x 0.5) / 2 = 1.5: sigma_xx = 2c (lambda^2 - 1/lambda) on the
  // current cross-section 1/lambda; the pull support holds the body with +F.
  const double lambda = 1.5, sigma = 2 * (lambda * lambda - 1 / lambda);
  const auto& pull = steps.back().supports.back();
  ASSERT_EQ(pull.name, "pull");
  EXPECT_NEAR(pull.force[0], sigma / lambda, 1e-8 * sigma);
  const StateFigures s = stateFigures(model);
  EXPECT_NEAR(s.stress[0].min, sigma, 1e-8 * sigma);
  EXPECT_NEAR(s.stress[0].max, sigma, 1e-8 * sigma);
  EXPECT_NEAR(s.stress[1].max, 0, 1e-8 * sigma);
  EXPECT_LE(s.volumeChange, 1e-10);
}

// What a failed increment undoes: multipliers and history come back exactly.
// Monolithic: steps alone until told otherwise, a Newton solve for one pass
// when told, and nested after PassPolicy::kMonolithicPasses. Nested: never a
// step alone.
TEST(PassPolicy, MonolithicStepsAloneUntilANewtonSolveIsAskedFor) {
  PassPolicy monolithic(true);
  EXPECT_TRUE(monolithic.stepAlone(1));
  EXPECT_TRUE(monolithic.stepAlone(2));
  monolithic.newtonNext();
  EXPECT_FALSE(monolithic.stepAlone(3));
  EXPECT_TRUE(monolithic.stepAlone(4));
  EXPECT_TRUE(monolithic.stepAlone(PassPolicy::kMonolithicPasses));
  EXPECT_FALSE(monolithic.stepAlone(PassPolicy::kMonolithicPasses + 1));
  PassPolicy nested(false);
  for (int it = 1; it <= 3; ++it) EXPECT_FALSE(nested.stepAlone(it));
}

TEST(EffectState, RestoreUndoesChangedMultipliers) {
  const Scene scene = stretchScene();
  Model model(scene, Tpetra::getDefaultComm());
  Log log(model.rank0, true, {});
  LoadStepper stepper(model, log, false, 0.0);
  StepRecord rec;
  rec.step = 1, rec.time = 1;
  std::string failure;
  ASSERT_TRUE(stepper.advance(rec, failure)) << failure;
  const auto& effects = model.effects();
  const EffectState saved = saveState(effects);
  const auto anchors = multipliers(effects, true);
  ASSERT_FALSE(anchors.empty());
  double size = 0;
  for (double p : anchors) size = std::max(size, std::fabs(p));
  EXPECT_GT(size, 0.1);  // the stretched block's pressure anchors
  setMultipliers(effects, std::vector<double>(anchors.size(), 0.0), true);
  EXPECT_EQ(multipliers(effects, true), std::vector<double>(anchors.size(), 0.0));
  restoreState(effects, saved);
  EXPECT_EQ(multipliers(effects, true), anchors);
}

// The start-up defaults (src/mpi_startup.hpp) name Open MPI's ob1 layer
// unless a fast network device exists or the user names a layer or a network
// module; a user's setting wins.
TEST(MpiStartup, DefaultsKeepTheUsersSettings) {
  const char* pml = std::getenv("OMPI_MCA_pml");
  const char* mtl = std::getenv("OMPI_MCA_mtl");
  const std::string savedPml = pml ? pml : "", savedMtl = mtl ? mtl : "";
  auto value = [](const char* name) { const char* v = std::getenv(name); return std::string(v ? v : "(unset)"); };

  unsetenv("OMPI_MCA_pml"), unsetenv("OMPI_MCA_mtl");
  setMpiStartupDefaults();
  EXPECT_EQ(value("OMPI_MCA_pml"), fastFabricPresent() ? "(unset)" : "ob1");

  setenv("OMPI_MCA_pml", "ucx", 1);
  setMpiStartupDefaults();
  EXPECT_EQ(value("OMPI_MCA_pml"), "ucx");

  unsetenv("OMPI_MCA_pml"), setenv("OMPI_MCA_mtl", "psm2", 1);
  setMpiStartupDefaults();
  EXPECT_EQ(value("OMPI_MCA_pml"), "(unset)");

  savedPml.empty() ? unsetenv("OMPI_MCA_pml") : setenv("OMPI_MCA_pml", savedPml.c_str(), 1);
  savedMtl.empty() ? unsetenv("OMPI_MCA_mtl") : setenv("OMPI_MCA_mtl", savedMtl.c_str(), 1);
}

// setTcpNoDelay (src/mpi_startup.hpp): a loopback TCP connection sends at once
// afterwards, at both ends; a Unix socket pair is left as it was.
TEST(MpiStartup, TcpSocketsSendAtOnce) {
  const int listener = socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(listener, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t size = sizeof address;
  ASSERT_EQ(bind(listener, reinterpret_cast<sockaddr*>(&address), size), 0);
  ASSERT_EQ(listen(listener, 1), 0);
  ASSERT_EQ(getsockname(listener, reinterpret_cast<sockaddr*>(&address), &size), 0);
  const int client = socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_EQ(connect(client, reinterpret_cast<sockaddr*>(&address), size), 0);
  const int server = accept(listener, nullptr, nullptr);
  ASSERT_GE(server, 0);
  int pair[2];
  ASSERT_EQ(socketpair(AF_UNIX, SOCK_STREAM, 0, pair), 0);
  auto noDelay = [](int fd) {
    int on = -1;
    socklen_t length = sizeof on;
    return getsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, &length) == 0 ? on : -1;
  };
  EXPECT_EQ(noDelay(client), 0);  // Nagle's algorithm on, as the kernel opens it
  EXPECT_GE(setTcpNoDelay(), 3);   // the listener, both ends, and any MPI holds
  EXPECT_NE(noDelay(client), 0);
  EXPECT_NE(noDelay(server), 0);
  EXPECT_EQ(noDelay(pair[0]), -1);  // not a TCP socket: untouched
  for (int fd : {client, server, listener, pair[0], pair[1]}) close(fd);
}
