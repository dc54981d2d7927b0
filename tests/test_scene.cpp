// Scene loading and validation (interface.md, "Scene file" and "Command line"):
// every bad input throws capstan::InputError whose message names the scene file and
// the parameter path; good input loads with defaults filled in, --set overrides a
// parameter by its path, and --output overrides Output/Directory.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "errors.hpp"
#include "scene.hpp"

using namespace capstan;
namespace fs = std::filesystem;

namespace {

// A temporary directory for the scene files, removed after the suite.
class SceneTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("capstan-test-scene-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  // Writes TEXT to a fresh file named after the running test and returns its path.
  static std::string write(const std::string& text, const std::string& suffix = ".xml") {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    const fs::path p = dir_ / (std::string(info->name()) + "_" + std::to_string(counter_++) + suffix);
    std::ofstream out(p, std::ios::binary);
    out << text;
    return p.string();
  }

  static fs::path dir_;
  static int counter_;
};

fs::path SceneTest::dir_;
int SceneTest::counter_ = 0;

// A complete, valid scene; the pieces can be replaced to make it bad.
struct SceneText {
  std::string title = R"X(<Parameter name="Title" type="string" value="test scene"/>)X";
  std::string mesh = R"X(
  <ParameterList name="Mesh">
    <Parameter name="Type"  type="string"        value="Box"/>
    <Parameter name="Min"   type="Array(double)" value="{0, 0, 0}"/>
    <Parameter name="Max"   type="Array(double)" value="{2, 1, 1}"/>
    <Parameter name="Cells" type="Array(int)"    value="{4, 2, 2}"/>
  </ParameterList>)X";
  std::string material = R"X(
  <ParameterList name="Material">
    <Parameter name="c" type="double" value="1"/>
    <Parameter name="Pressure Penalty" type="double" value="1e-3"/>
  </ParameterList>)X";
  std::string supports = R"X(
  <ParameterList name="Supports">
    <ParameterList name="base">
      <Parameter name="Face" type="string" value="ymin"/>
      <Parameter name="Type" type="string" value="Fixed"/>
    </ParameterList>
    <ParameterList name="pull">
      <Parameter name="Face" type="string" value="xmax"/>
      <Parameter name="Type" type="string" value="Displacement"/>
      <Parameter name="Components" type="string" value="x"/>
      <Parameter name="Velocity" type="Array(double)" value="{0.2, 0, 0}"/>
    </ParameterList>
    <ParameterList name="wall">
      <Parameter name="Face" type="string" value="xmin"/>
      <Parameter name="Type" type="string" value="Foundation"/>
      <Parameter name="Components" type="string" value="x"/>
      <Parameter name="Stiffness" type="double" value="1"/>
    </ParameterList>
  </ParameterList>)X";
  std::string time = R"X(
  <ParameterList name="Time">
    <Parameter name="Steps"     type="int"    value="5"/>
    <Parameter name="Step Size" type="double" value="1"/>
  </ParameterList>)X";
  std::string solver = R"X(
  <ParameterList name="Solver">
    <Parameter name="Linear Solver" type="string" value="GMRES"/>
  </ParameterList>)X";
  std::string output = R"X(
  <ParameterList name="Output">
    <Parameter name="Directory" type="string" value="out/test"/>
  </ParameterList>)X";

  std::string str() const {
    return "<ParameterList name=\"Scene\">\n  " + title + mesh + material + supports + time + solver +
           output + "\n</ParameterList>\n";
  }
};

// Replaces the first occurrence of FROM in TEXT by TO (FROM must be there).
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test bug: '" << from << "' not in the scene";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// Loads FILE and expects an InputError whose message contains the file name and
// every one of NEEDLES (the parameter path, and what is wrong where given).
void expectInputError(const std::string& file, const std::vector<std::string>& needles,
                      const std::vector<std::string>& sets = {}, const std::string& output = "") {
  try {
    loadScene(file, sets, output);
    ADD_FAILURE() << "no InputError for " << file << " (expected one naming " << needles.front() << ")";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(file), std::string::npos) << "message does not name the file " << file << ":\n  " << what;
    for (const auto& n : needles)
      EXPECT_NE(what.find(n), std::string::npos) << "message does not contain '" << n << "':\n  " << what;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected capstan::InputError, got another exception: " << e.what();
  }
}

// The valid scene with FROM replaced by TO.
std::string sceneWith(const std::string& from, const std::string& to) {
  return replaced(SceneText().str(), from, to);
}

// ---------------------------------------------------------------------------
// The file itself

TEST_F(SceneTest, ValidSceneLoads) {
  const std::string file = write(SceneText().str());
  const Scene s = loadScene(file, {}, "");
  EXPECT_EQ(s.file, file);
  EXPECT_EQ(s.title, "test scene");
  EXPECT_EQ(s.mesh.type, MeshSpec::Type::Box);
  EXPECT_EQ(s.mesh.cells, (std::array<int, 3>{4, 2, 2}));
  EXPECT_EQ(s.mesh.max, (std::array<double, 3>{2, 1, 1}));
  EXPECT_EQ(s.c, 1.0);
  EXPECT_EQ(s.pressurePenalty, 1e-3);
  EXPECT_EQ(s.steps, 5);
  EXPECT_EQ(s.stepSize, 1.0);
  EXPECT_EQ(s.outputDirectory, "out/test");
  ASSERT_EQ(s.supports.size(), 3u);
  EXPECT_EQ(s.supports[0].name, "base");
  EXPECT_EQ(s.supports[0].components, (std::array<bool, 3>{true, true, true}));
  EXPECT_EQ(s.supports[1].name, "pull");
  EXPECT_EQ(s.supports[1].type, SupportSpec::Type::Displacement);
  EXPECT_EQ(s.supports[1].components, (std::array<bool, 3>{true, false, false}));
  EXPECT_EQ(s.supports[1].velocity, (std::array<double, 3>{0.2, 0, 0}));
  EXPECT_EQ(s.supports[2].type, SupportSpec::Type::Foundation);
  EXPECT_EQ(s.supports[2].stiffness, 1.0);
  EXPECT_TRUE(s.capstans.empty());
}

TEST_F(SceneTest, DefaultsAreFilledIn) {
  // Only the mesh and one support given: everything else takes its default.
  const std::string file = write(R"X(<ParameterList name="Scene">
  <ParameterList name="Mesh">
    <Parameter name="Cells" type="Array(int)" value="{2, 3, 4}"/>
  </ParameterList>
  <ParameterList name="Material">
    <Parameter name="c" type="double" value="3"/>
  </ParameterList>
  <ParameterList name="Supports">
    <ParameterList name="roll">
      <Parameter name="Face" type="string" value="zmin"/>
      <Parameter name="Type" type="string" value="Roller"/>
    </ParameterList>
  </ParameterList>
</ParameterList>
)X");
  const Scene s = loadScene(file, {}, "");
  const auto valid = validParameters();
  EXPECT_EQ(s.title, "");
  EXPECT_EQ(s.mesh.type, MeshSpec::Type::Box);
  EXPECT_EQ(s.mesh.min, (std::array<double, 3>{0, 0, 0}));
  EXPECT_EQ(s.mesh.max, (std::array<double, 3>{1, 1, 1}));
  EXPECT_EQ(s.mesh.cells, (std::array<int, 3>{2, 3, 4}));
  EXPECT_EQ(s.c, 3.0);
  EXPECT_EQ(s.pressurePenalty, valid.sublist("Material").get<double>("Pressure Penalty"));
  EXPECT_EQ(s.steps, valid.sublist("Time").get<int>("Steps"));
  EXPECT_EQ(s.stepSize, valid.sublist("Time").get<double>("Step Size"));
  EXPECT_EQ(s.outputDirectory, valid.sublist("Output").get<std::string>("Directory"));
  EXPECT_TRUE(s.writeFields);
  ASSERT_EQ(s.supports.size(), 1u);
  EXPECT_EQ(s.supports[0].components, (std::array<bool, 3>{true, true, true}))
      << "a Roller without Components takes the default \"xyz\"";
  // The resolved lists hold every parameter of the valid list.
  const auto& sol = s.resolved.sublist("Solver");
  for (const char* n : {"Linear Solver", "Preconditioner", "Line Search"})
    EXPECT_EQ(sol.get<std::string>(n), valid.sublist("Solver").get<std::string>(n)) << n;
  for (const char* n : {"Linear Tolerance", "Newton Relative Tolerance", "Volume Tolerance",
                        "Minimum Solve Penalty"})
    EXPECT_EQ(sol.get<double>(n), valid.sublist("Solver").get<double>(n)) << n;
  EXPECT_EQ(sol.get<int>("Max Newton Iterations"), valid.sublist("Solver").get<int>("Max Newton Iterations"));
  EXPECT_TRUE(s.resolved.sublist("Material").isParameter("Model"));
  EXPECT_EQ(s.resolved.sublist("Supports").sublist("roll").get<std::string>("Components"), "xyz");
}

TEST_F(SceneTest, IntAcceptedForDouble) {
  std::string text = SceneText().str();
  text = replaced(text, R"X(<Parameter name="c" type="double" value="1"/>)X",
                  R"X(<Parameter name="c" type="int" value="2"/>)X");
  text = replaced(text, R"X(<Parameter name="Step Size" type="double" value="1"/>)X",
                  R"X(<Parameter name="Step Size" type="int" value="3"/>)X");
  text = replaced(text, R"X(<Parameter name="Max"   type="Array(double)" value="{2, 1, 1}"/>)X",
                  R"X(<Parameter name="Max"   type="Array(int)" value="{3, 2, 1}"/>)X");
  const Scene s = loadScene(write(text), {}, "");
  EXPECT_EQ(s.c, 2.0);
  EXPECT_EQ(s.stepSize, 3.0);
  EXPECT_EQ(s.mesh.max, (std::array<double, 3>{3, 2, 1}));
  EXPECT_EQ(s.resolved.sublist("Material").get<double>("c"), 2.0);
}

TEST_F(SceneTest, MalformedXml) {
  // Unclosed element.
  const std::string f1 = write("<ParameterList name=\"Scene\">\n  <ParameterList name=\"Mesh\">\n</ParameterList>\n");
  expectInputError(f1, {"XML"});
  // Truncated in the middle of a tag.
  std::string full = SceneText().str();
  const std::string f2 = write(full.substr(0, full.size() / 2));
  expectInputError(f2, {"XML"});
  // Not XML at all.
  const std::string f3 = write("Mesh/Cells = {4, 2, 2}\n");
  expectInputError(f3, {});
}

TEST_F(SceneTest, EmptyFile) {
  expectInputError(write(""), {"empty"});
  expectInputError(write("  \n\t\n"), {"empty"});
}

TEST_F(SceneTest, BinaryGarbage) {
  std::string garbage;
  for (int i = 0; i < 512; ++i) garbage += char((i * 37 + 11) % 256);
  expectInputError(write(garbage, ".bin"), {});
  // Binary data after a valid start.
  expectInputError(write(std::string("<ParameterList name=\"Scene\">\x01\x02\x00\x7f", 32)), {});
}

TEST_F(SceneTest, MissingFile) {
  const std::string file = (dir_ / "no-such-scene.xml").string();
  expectInputError(file, {});
}

// ---------------------------------------------------------------------------
// Names and types

TEST_F(SceneTest, UnknownParameter) {
  expectInputError(write(sceneWith(R"X(<Parameter name="Cells" )X", R"X(<Parameter name="Cels" )X")),
                   {"Mesh/Cels", "unknown"});
  expectInputError(write(sceneWith(R"X(<Parameter name="c" )X", R"X(<Parameter name="C" )X")), {"Material/C"});
  // An unknown top-level parameter.
  expectInputError(write(sceneWith(R"X(<Parameter name="Title" )X", R"X(<Parameter name="Titel" )X")), {"Titel"});
  // An unknown parameter inside a named support.
  expectInputError(write(sceneWith(R"X(<Parameter name="Stiffness" )X", R"X(<Parameter name="Stifness" )X")),
                   {"Supports/wall/Stifness"});
}

TEST_F(SceneTest, MisspelledSublist) {
  expectInputError(write(sceneWith(R"X(<ParameterList name="Material">)X", R"X(<ParameterList name="Materail">)X")),
                   {"Materail"});
  expectInputError(write(sceneWith(R"X(<ParameterList name="Supports">)X", R"X(<ParameterList name="Support">)X")),
                   {"Support"});
  expectInputError(write(sceneWith(R"X(<ParameterList name="Solver">)X",
                                   R"X(<ParameterList name="Solver"><ParameterList name="Stratimikus"></ParameterList>)X")),
                   {"Solver/Stratimikus"});
  // A sublist where a parameter belongs.
  expectInputError(write(sceneWith(R"X(<Parameter name="Title" type="string" value="test scene"/>)X",
                                   R"X(<ParameterList name="Title"></ParameterList>)X")),
                   {"Title"});
}

TEST_F(SceneTest, WrongType) {
  expectInputError(write(sceneWith(R"X(<Parameter name="c" type="double" value="1"/>)X",
                                   R"X(<Parameter name="c" type="string" value="one"/>)X")),
                   {"Material/c"});
  expectInputError(write(sceneWith(R"X(<Parameter name="c" type="double" value="1"/>)X",
                                   R"X(<Parameter name="c" type="string" value="1"/>)X")),
                   {"Material/c"});
  expectInputError(write(sceneWith(R"X(<Parameter name="Steps"     type="int"    value="5"/>)X",
                                   R"X(<Parameter name="Steps"     type="double" value="5.5"/>)X")),
                   {"Time/Steps"});
  expectInputError(write(sceneWith(R"X(<Parameter name="Cells" type="Array(int)"    value="{4, 2, 2}"/>)X",
                                   R"X(<Parameter name="Cells" type="Array(double)" value="{4, 2, 2}"/>)X")),
                   {"Mesh/Cells"});
  expectInputError(write(sceneWith(R"X(<Parameter name="Face" type="string" value="ymin"/>)X",
                                   R"X(<Parameter name="Face" type="int" value="3"/>)X")),
                   {"Supports/base/Face"});
}

// Numbers must read exactly as their type: Teuchos alone would keep a prefix
// ("5.5" as the int 5) or read nothing as 0 ("abc", "nan").
TEST_F(SceneTest, NumbersReadStrictly) {
  const std::string c = R"X(<Parameter name="c" type="double" value="1"/>)X";
  const std::string steps = R"X(<Parameter name="Steps"     type="int"    value="5"/>)X";
  const std::string min = R"X(<Parameter name="Min"   type="Array(double)" value="{0, 0, 0}"/>)X";
  for (const char* bad : {"abc", "", "nan", "inf", "1e999", "0x10", "1 2"})
    expectInputError(write(sceneWith(c, std::string(R"X(<Parameter name="c" type="double" value=")X") + bad + "\"/>")),
                     {"Material/c", "type double"});
  for (const char* bad : {"5.5", "1e3", "99999999999", "five"})
    expectInputError(write(sceneWith(steps, std::string(R"X(<Parameter name="Steps" type="int" value=")X") + bad + "\"/>")),
                     {"Time/Steps", "type int"});
  for (const char* bad : {"{nan, 0, 0}", "{0, 0, 0", "0, 0, 0", "{0,,0}", "{0, 0,}"})
    expectInputError(write(sceneWith(min, std::string(R"X(<Parameter name="Min" type="Array(double)" value=")X") + bad + "\"/>")),
                     {"Mesh/Min", "Array(double)"});
  // Spaces around numbers are fine.
  const Scene sc = loadScene(write(sceneWith(c, R"X(<Parameter name="c" type="double" value=" 2.5 "/>)X")), {}, "");
  EXPECT_EQ(sc.c, 2.5);
  expectInputError(write(sceneWith(c, R"X(<Parameter name="c" type="complex" value="1"/>)X")), {"Material/c", "complex"});
}

TEST_F(SceneTest, XmlStructure) {
  const std::string c = R"X(<Parameter name="c" type="double" value="1"/>)X";
  expectInputError(write(sceneWith(c, c + c)), {"Material/c", "given twice"});
  expectInputError(write(sceneWith(R"X(<ParameterList name="Time">)X",
                                   R"X(<ParameterList name="Time"></ParameterList><ParameterList name="Time">)X")),
                   {"Time", "given twice"});
  expectInputError(write(sceneWith(c, R"X(<Parameter name="c" type="double"/>)X")), {"Material/c", "value"});
  expectInputError(write(sceneWith(c, R"X(<Parameter type="double" value="1"/>)X")), {"Material", "name"});
  expectInputError(write(sceneWith(c, c + "<Foo/>")), {"Material", "<Foo>"});
  // Deep nesting is refused before the recursive Teuchos reader sees it.
  std::string deep = "<ParameterList name=\"Scene\">";
  for (int i = 0; i < 20000; ++i) deep += "<ParameterList name=\"a\">";
  for (int i = 0; i < 20000; ++i) deep += "</ParameterList>";
  expectInputError(write(deep + "</ParameterList>"), {"nested deeper"});
  expectInputError(write("<Foo name=\"Scene\"></Foo>"), {"<ParameterList>"});
  // parseScene: the same on text, named as given.
  EXPECT_THROW(parseScene("<ParameterList name=\"Scene\"><Parameter name=\"Titel\" type=\"string\" value=\"\"/>"
                          "</ParameterList>", "text.xml", {}, ""),
               InputError);
  EXPECT_EQ(parseScene(SceneText().str(), "text.xml", {}, "").file, "text.xml");
}

TEST_F(SceneTest, MeshSizeAndFiniteValues) {
  expectInputError(write(sceneWith(R"X(value="{4, 2, 2}")X", R"X(value="{100000, 100000, 100000}")X")),
                   {"Mesh/Cells", "too many"});
  expectInputError(write(SceneText().str()), {"Mesh/Min", "cannot read"}, {"Mesh/Min={0, 1e999, 0}"});
  expectInputError(write(SceneText().str()), {"Output/Checkpoint Every"}, {"Output/Checkpoint Every=-1"});
  EXPECT_EQ(loadScene(write(SceneText().str()), {"Output/Checkpoint Every=3"}, "").checkpointEvery, 3);
  EXPECT_EQ(loadScene(write(SceneText().str()), {}, "").checkpointEvery, 0);
}

// ---------------------------------------------------------------------------
// Values

TEST_F(SceneTest, CellsMustBePositive) {
  const std::string from = R"X(value="{4, 2, 2}")X";
  for (const char* bad : {"{0, 2, 2}", "{4, 0, 2}", "{4, 2, 0}", "{-1, 2, 2}", "{4, 2, -3}"})
    expectInputError(write(sceneWith(from, std::string("value=\"") + bad + "\"")), {"Mesh/Cells"});
}

TEST_F(SceneTest, CellsNeedThreeEntries) {
  const std::string from = R"X(value="{4, 2, 2}")X";
  expectInputError(write(sceneWith(from, R"X(value="{4, 2}")X")), {"Mesh/Cells"});
  expectInputError(write(sceneWith(from, R"X(value="{4, 2, 2, 2}")X")), {"Mesh/Cells"});
  expectInputError(write(sceneWith(R"X(value="{2, 1, 1}")X", R"X(value="{2, 1}")X")), {"Mesh/Max"});
}

TEST_F(SceneTest, MaxMustExceedMin) {
  const std::string from = R"X(value="{2, 1, 1}")X";
  expectInputError(write(sceneWith(from, R"X(value="{2, 0, 1}")X")), {"Mesh/Max"});    // equal
  expectInputError(write(sceneWith(from, R"X(value="{-1, 1, 1}")X")), {"Mesh/Max"});   // below
  expectInputError(write(sceneWith(from, R"X(value="{2, 1, -0.5}")X")), {"Mesh/Max"});
}

TEST_F(SceneTest, MaterialConstantPositive) {
  const std::string from = R"X(<Parameter name="c" type="double" value="1"/>)X";
  for (const char* bad : {"0", "-1", "-1e-12"})
    expectInputError(write(sceneWith(from, std::string(R"X(<Parameter name="c" type="double" value=")X") + bad + "\"/>")),
                     {"Material/c"});
}

TEST_F(SceneTest, PressurePenaltyNotNegative) {
  const std::string from = R"X(<Parameter name="Pressure Penalty" type="double" value="1e-3"/>)X";
  for (const char* bad : {"-1e-300", "-1e-3"})
    expectInputError(
        write(sceneWith(from, std::string(R"X(<Parameter name="Pressure Penalty" type="double" value=")X") + bad + "\"/>")),
        {"Material/Pressure Penalty"});
}

TEST_F(SceneTest, TimeStepsAtLeastOne) {
  const std::string from = R"X(<Parameter name="Steps"     type="int"    value="5"/>)X";
  expectInputError(write(sceneWith(from, R"X(<Parameter name="Steps" type="int" value="0"/>)X")), {"Time/Steps"});
  expectInputError(write(sceneWith(from, R"X(<Parameter name="Steps" type="int" value="-2"/>)X")), {"Time/Steps"});
}

TEST_F(SceneTest, StepSizePositive) {
  const std::string from = R"X(<Parameter name="Step Size" type="double" value="1"/>)X";
  expectInputError(write(sceneWith(from, R"X(<Parameter name="Step Size" type="double" value="0"/>)X")),
                   {"Time/Step Size"});
  expectInputError(write(sceneWith(from, R"X(<Parameter name="Step Size" type="double" value="-0.1"/>)X")),
                   {"Time/Step Size"});
}

TEST_F(SceneTest, UnknownSupportType) {
  expectInputError(write(sceneWith(R"X(<Parameter name="Type" type="string" value="Fixed"/>)X",
                                   R"X(<Parameter name="Type" type="string" value="Clamped"/>)X")),
                   {"Supports/base/Type", "Clamped"});
  expectInputError(write(sceneWith(R"X(<Parameter name="Type" type="string" value="Fixed"/>)X",
                                   R"X(<Parameter name="Type" type="string" value="fixed"/>)X")),
                   {"Supports/base/Type"});
}

TEST_F(SceneTest, UnknownFace) {
  expectInputError(write(sceneWith(R"X(<Parameter name="Face" type="string" value="ymin"/>)X",
                                   R"X(<Parameter name="Face" type="string" value="bottom"/>)X")),
                   {"Supports/base/Face", "bottom"});
  expectInputError(write(sceneWith(R"X(<Parameter name="Face" type="string" value="xmax"/>)X",
                                   R"X(<Parameter name="Face" type="string" value=""/>)X")),
                   {"Supports/pull/Face"});
}

TEST_F(SceneTest, BadComponents) {
  const std::string from = R"X(<Parameter name="Components" type="string" value="x"/>)X";
  for (const char* bad : {"q", "xx", "", "xq", "w"})
    expectInputError(
        write(sceneWith(from, std::string(R"X(<Parameter name="Components" type="string" value=")X") + bad + "\"/>")),
        {"Supports/pull/Components"});
}

TEST_F(SceneTest, FoundationStiffnessPositive) {
  const std::string from = R"X(<Parameter name="Stiffness" type="double" value="1"/>)X";
  for (const char* bad : {"0", "-2"})
    expectInputError(
        write(sceneWith(from, std::string(R"X(<Parameter name="Stiffness" type="double" value=")X") + bad + "\"/>")),
        {"Supports/wall/Stiffness"});
}

TEST_F(SceneTest, BadSolverNames) {
  const std::string from = R"X(<Parameter name="Linear Solver" type="string" value="GMRES"/>)X";
  expectInputError(write(sceneWith(from, R"X(<Parameter name="Linear Solver" type="string" value="MINRES"/>)X")),
                   {"Solver/Linear Solver", "MINRES"});
  expectInputError(write(sceneWith(from, R"X(<Parameter name="Preconditioner" type="string" value="AMG"/>)X")),
                   {"Solver/Preconditioner", "AMG"});
  expectInputError(write(sceneWith(from, R"X(<Parameter name="Line Search" type="string" value="Wolfe"/>)X")),
                   {"Solver/Line Search", "Wolfe"});
  expectInputError(write(sceneWith(from, R"X(<Parameter name="Predictor" type="string" value="Secant"/>)X")),
                   {"Solver/Predictor", "Secant"});
}

// ---------------------------------------------------------------------------
// --set and --output

TEST_F(SceneTest, SetOverrides) {
  const std::string file = write(SceneText().str());
  const Scene s = loadScene(file, {"Mesh/Cells={8,2,2}", "Material/c=2"}, "");
  EXPECT_EQ(s.mesh.cells, (std::array<int, 3>{8, 2, 2}));
  EXPECT_EQ(s.c, 2.0);
  EXPECT_EQ(s.resolved.sublist("Material").get<double>("c"), 2.0);
  // Other values untouched.
  EXPECT_EQ(s.pressurePenalty, 1e-3);
  EXPECT_EQ(s.mesh.max, (std::array<double, 3>{2, 1, 1}));
}

TEST_F(SceneTest, AccuracyPresets) {
  const std::string file = write(SceneText().str());
  const std::array<int, 3> cells = loadScene(file, {}, "").mesh.cells;
  const Scene scene = loadScene(file, {"Accuracy=Scene"}, "");
  EXPECT_EQ(scene.mesh.cells, cells);
  EXPECT_EQ(scene.solver.newtonRelativeTolerance, 1e-10);
  const Scene draft = loadScene(file, {"Accuracy=Draft"}, "");
  EXPECT_EQ(draft.mesh.cells, cells);
  EXPECT_EQ(draft.solver.newtonRelativeTolerance, 1e-6);
  // A tolerance the scene sets itself wins over the preset.
  const Scene draftOwn = loadScene(file, {"Accuracy=Draft", "Solver/Newton Relative Tolerance=1e-9"}, "");
  EXPECT_EQ(draftOwn.solver.newtonRelativeTolerance, 1e-9);
  const Scene standard = loadScene(file, {"Accuracy=Standard"}, "");
  const Scene fine = loadScene(file, {"Accuracy=Fine"}, "");
  for (int d = 0; d < 3; ++d) {
    EXPECT_EQ(standard.mesh.cells[d], 2 * cells[d]);
    EXPECT_EQ(fine.mesh.cells[d], 4 * cells[d]);
  }
  EXPECT_EQ(fine.resolved.get<std::string>("Accuracy"), "Fine");
  expectInputError(file, {"'Accuracy'", "'Coarse' is not an accuracy preset"}, {"Accuracy=Coarse"});
}

TEST_F(SceneTest, MeshParametersOfTheOtherType) {
  const std::string file = write(SceneText().str());
  expectInputError(file, {"'Mesh/Inner Radius'", "Mesh/Type = Box"}, {"Mesh/Inner Radius=2"});
  expectInputError(file, {"'Mesh/Min'", "Mesh/Type = Annulus"}, {"Mesh/Type=Annulus"});
}

TEST_F(SceneTest, BodyForce) {
  const std::string file = write(SceneText().str());
  EXPECT_EQ(loadScene(file, {}, "").bodyForce, (std::array<double, 3>{0, 0, 0}));
  EXPECT_EQ(loadScene(file, {"Loads/Body Force={0, -9.81, 0}"}, "").bodyForce,
            (std::array<double, 3>{0, -9.81, 0}));
  expectInputError(file, {"'Loads/Body Force'", "expected 3 values"}, {"Loads/Body Force={1, 2}"});
}

TEST_F(SceneTest, SetReachesNamedObjectsAndAbsentSublists) {
  const std::string file = write(SceneText().str());
  const Scene s = loadScene(file,
                            {"Supports/pull/Velocity={-0.5, 0, 0.25}", "Time/Steps=7", "Solver/Line Search=Full Step",
                             "Solver/Max Newton Iterations=3", "Title=changed", "Material/Pressure Penalty=1e-13"},
                            "");
  ASSERT_EQ(s.supports.size(), 3u);
  EXPECT_EQ(s.supports[1].velocity, (std::array<double, 3>{-0.5, 0, 0.25}));
  EXPECT_EQ(s.steps, 7);
  EXPECT_EQ(s.solver.lineSearch, SolverSettings::LineSearch::FullStep);
  EXPECT_EQ(s.solver.maxNewtonIterations, 3);
  EXPECT_EQ(s.title, "changed");
  EXPECT_EQ(s.pressurePenalty, 1e-13);
  // A parameter the scene file does not give (its sublist absent too): typed from the valid list.
  const std::string bare = write(R"X(<ParameterList name="Scene">
  <ParameterList name="Mesh"><Parameter name="Cells" type="Array(int)" value="{1, 1, 1}"/></ParameterList>
</ParameterList>
)X");
  const Scene b = loadScene(bare, {"Solver/Linear Solver=Direct", "Time/Step Size=0.5"}, "");
  EXPECT_EQ(b.solver.linearSolver, SolverSettings::LinearSolver::Direct);
  EXPECT_EQ(b.stepSize, 0.5);
}

TEST_F(SceneTest, SetValuesAreValidated) {
  // A value that parses but is out of range fails like the same value in the file.
  const std::string file = write(SceneText().str());
  expectInputError(file, {"Mesh/Cells"}, {"Mesh/Cells={8,0,2}"});
  expectInputError(file, {"Mesh/Cells"}, {"Mesh/Cells={8,2}"});
  expectInputError(file, {"Material/c"}, {"Material/c=0"});
  expectInputError(file, {"Time/Steps"}, {"Time/Steps=0"});
  expectInputError(file, {"Supports/pull/Components"}, {"Supports/pull/Components=xx"});
  expectInputError(file, {"Solver/Linear Solver"}, {"Solver/Linear Solver=LU"});
}

TEST_F(SceneTest, SetUnknownPath) {
  const std::string file = write(SceneText().str());
  expectInputError(file, {"Mesh/Cels"}, {"Mesh/Cels={8,2,2}"});
  expectInputError(file, {"Materail/c"}, {"Materail/c=2"});
  expectInputError(file, {"Solver/Foo"}, {"Solver/Foo=1"});
  expectInputError(file, {"Supports/pull/Stifness"}, {"Supports/pull/Stifness=2"});
}

TEST_F(SceneTest, SetUnparsableValue) {
  const std::string file = write(SceneText().str());
  expectInputError(file, {"Material/c", "abc"}, {"Material/c=abc"});
  expectInputError(file, {"Material/c"}, {"Material/c=1.5x"});
  expectInputError(file, {"Material/c"}, {"Material/c="});
  expectInputError(file, {"Time/Steps"}, {"Time/Steps=2.5"});
  expectInputError(file, {"Time/Steps"}, {"Time/Steps=five"});
}

TEST_F(SceneTest, SetWithoutEquals) {
  const std::string file = write(SceneText().str());
  expectInputError(file, {"Material/c"}, {"Material/c"});
}

TEST_F(SceneTest, OutputOverridesDirectory) {
  const std::string file = write(SceneText().str());
  EXPECT_EQ(loadScene(file, {}, "").outputDirectory, "out/test");
  const Scene s = loadScene(file, {}, "/tmp/somewhere/else");
  EXPECT_EQ(s.outputDirectory, "/tmp/somewhere/else");
  EXPECT_EQ(s.resolved.sublist("Output").get<std::string>("Directory"), "/tmp/somewhere/else");
  // --output wins over --set Output/Directory.
  EXPECT_EQ(loadScene(file, {"Output/Directory=from-set"}, "from-output").outputDirectory, "from-output");
  EXPECT_EQ(loadScene(file, {"Output/Directory=from-set"}, "").outputDirectory, "from-set");
}

TEST_F(SceneTest, ShippedInputsValidate) {
  // The scenes in inputs/ that the integration tests run all load
  // (CAPSTAN_INPUTS_DIR is set by CMake).
#ifdef CAPSTAN_INPUTS_DIR
  for (const char* name : {"uniaxial.xml", "shear.xml", "default.xml", "squeeze.xml", "block40.xml", "two-capstans.xml",
                           "seed/g1.xml", "seed/g2.xml", "seed/g3.xml", "seed/h1.xml", "seed/h2.xml",
                           "seed/h3.xml", "seed/h4.xml", "seed/h5.xml", "seed/h4-study.xml", "seed/h5-study.xml"}) {
    const std::string file = std::string(CAPSTAN_INPUTS_DIR) + "/" + name;
    EXPECT_NO_THROW(loadScene(file, {}, "")) << file;
  }
#else
  GTEST_SKIP() << "CAPSTAN_INPUTS_DIR not defined";
#endif
}

// ---------------------------------------------------------------------------
// Capstans

#ifdef CAPSTAN_INPUTS_DIR
TEST_F(SceneTest, CapstanOfG1) {
  const Scene s = loadScene(std::string(CAPSTAN_INPUTS_DIR) + "/seed/g1.xml", {}, "");
  ASSERT_EQ(s.capstans.size(), 1u);
  const auto& c = s.capstans[0];
  EXPECT_EQ(c.name, "capstan");
  EXPECT_EQ(c.radius, 2.0);
  EXPECT_EQ(c.axisPoint, (std::array<double, 3>{3.5, 3.75, 0}));
  EXPECT_EQ(c.axisDirection, (std::array<double, 3>{0, 0, 1}));
  EXPECT_EQ(c.velocity, (std::array<double, 3>{0, -0.1, 0}));
  EXPECT_EQ(c.contactFaces, (std::vector<std::string>{"ymax"}));
  EXPECT_EQ(c.contact.method, ContactSettings::Method::AugmentedLagrangian);
  EXPECT_EQ(c.contact.quadrature, ContactSettings::Quadrature::Auto);
  EXPECT_EQ(c.contact.resolvedQuadrature(0.5, 1.0), ContactSettings::Quadrature::Nodal)
      << "Auto: the augmented Lagrangian uses the nodal rule";
  EXPECT_LT(c.contact.minimumSolvePenalty, 0) << "automatic solve penalty by default";
  const Scene p = loadScene(std::string(CAPSTAN_INPUTS_DIR) + "/seed/g1.xml",
                            {"Capstans/capstan/Contact/Method=Penalty"}, "");
  // G1's penalty 1e-3 against 1e-3 h / c: Gauss 2x2 for h / c below 1, nodal above.
  EXPECT_EQ(p.capstans[0].contact.resolvedQuadrature(0.99, 1.0), ContactSettings::Quadrature::Gauss2x2)
      << "Auto: the penalty method uses Gauss 2x2";
  EXPECT_EQ(p.capstans[0].contact.resolvedQuadrature(1.01, 1.0), ContactSettings::Quadrature::Nodal)
      << "Auto: a stiff penalty uses the nodal rule";
  EXPECT_EQ(p.capstans[0].contact.resolvedQuadrature(0.99, 1.0, true), ContactSettings::Quadrature::Nodal)
      << "Auto: exact stick (steady Coulomb) uses the nodal rule";
  const Scene named = loadScene(std::string(CAPSTAN_INPUTS_DIR) + "/seed/g1.xml",
                                {"Capstans/capstan/Contact/Method=Penalty", "Capstans/capstan/Contact/Quadrature=Gauss 3x3"}, "");
  EXPECT_EQ(named.capstans[0].contact.resolvedQuadrature(0.01, 1.0), ContactSettings::Quadrature::Gauss3x3);
}

TEST_F(SceneTest, CapstanInputErrors) {
  const std::string g1 = std::string(CAPSTAN_INPUTS_DIR) + "/seed/g1.xml";
  const std::string C = "Capstans/capstan/";
  expectInputError(g1, {C + "Radius"}, {C + "Radius=0"});
  expectInputError(g1, {C + "Axis Direction", "non-zero"}, {C + "Axis Direction={0,0,0}"});
  expectInputError(g1, {C + "Contact Faces", "'top'"}, {C + "Contact Faces=top"});
  expectInputError(g1, {C + "Contact/Method", "'Lagrange'"}, {C + "Contact/Method=Lagrange"});
  expectInputError(g1, {C + "Contact/Penalty"}, {C + "Contact/Penalty=-1e-3"});
  expectInputError(g1, {C + "Contact/Quadrature", "'Gauss 4x4'"}, {C + "Contact/Quadrature=Gauss 4x4"});
  expectInputError(g1, {C + "Contact/Quadrature", "Nodal"}, {C + "Contact/Quadrature=Gauss 2x2"});
  expectInputError(g1, {C + "Contact/Max Augmentations"}, {C + "Contact/Max Augmentations=0"});
  expectInputError(g1, {C + "Friction/Law", "'Stribeck'"}, {C + "Friction/Law=Stribeck"});
  expectInputError(g1, {C + "Friction/Coefficient"}, {C + "Friction/Law=Tanh", C + "Friction/Coefficient=-0.1"});
  expectInputError(g1, {C + "Friction/Regularization"}, {C + "Friction/Law=Tanh", C + "Friction/Regularization=0"});
  expectInputError(g1, {"Solver/Linear Solver", "non-symmetric"},
                   {C + "Friction/Law=Coulomb", "Solver/Linear Solver=CG"});
  expectInputError(g1, {C + "Angular Velocity", "cannot read"}, {C + "Angular Velocity=nan"});
}

// Axis directions of any scale: scaled by a power of two, so |beta|^2 neither
// under- nor overflows, and ordinary ones keep their bits.
TEST_F(SceneTest, AxisDirectionScale) {
  const std::string g1 = std::string(CAPSTAN_INPUTS_DIR) + "/seed/g1.xml";
  const std::string C = "Capstans/capstan/";
  EXPECT_EQ(loadScene(g1, {C + "Axis Direction={0.2, 0, 1}"}, "").capstans[0].axisDirection,
            (std::array<double, 3>{0.2, 0, 1}));
  EXPECT_EQ(loadScene(g1, {C + "Axis Direction={0, 0, 4}"}, "").capstans[0].axisDirection,
            (std::array<double, 3>{0, 0, 1}));
  for (const char* d : {"{0, 0, 1e-200}", "{0, 0, 1e200}", "{1e-300, 0, 3e-300}"}) {
    const auto b = loadScene(g1, {C + "Axis Direction=" + d}, "").capstans[0].axisDirection;
    const double m = std::max({std::fabs(b[0]), std::fabs(b[1]), std::fabs(b[2])});
    EXPECT_TRUE(m >= 1 && m < 2) << d << ": largest component " << m;
  }
}

// The fine sector's centre is an angle: taken modulo a turn, so that a huge
// one does not round the cells' angles to one value (NaN stresses).
TEST_F(SceneTest, FineSectorCentreModuloATurn) {
  const std::string slice = std::string(CAPSTAN_INPUTS_DIR) + "/pinch-roller-slice.xml";
  EXPECT_EQ(loadScene(slice, {}, "").mesh.fineSector[0], -65.0);
  EXPECT_EQ(loadScene(slice, {"Mesh/Fine Sector={295, 60, 0.6}"}, "").mesh.fineSector[0], -65.0);
  const double c = loadScene(slice, {"Mesh/Fine Sector={1e24, 60, 0.6}"}, "").mesh.fineSector[0];
  EXPECT_TRUE(c >= -180 && c <= 180) << c;
}

// The contact penalty's default is automatic: 2e-3 h / c for a plain penalty (1e-3 on G1's mesh,
// in any units), the study's 1e-3 for the augmented Lagrangian (its solves clamp it); a scene's
// own value is kept. A soft one is flagged by the run, which knows h
// (tests/integration/units.py; docs/contact.md, "Penalties in any units").
TEST_F(SceneTest, ContactPenaltyAutomatic) {
  const std::string g1 = std::string(CAPSTAN_INPUTS_DIR) + "/seed/g1.xml";
  const std::string P = "Capstans/capstan/Contact/Penalty=";
  const std::string plain = "Capstans/capstan/Contact/Method=Penalty";
  const auto automatic = loadScene(g1, {P + "0", plain}, "").capstans.at(0).contact;
  EXPECT_DOUBLE_EQ(automatic.resolvedPenalty(0.5, 1.0), 1e-3);
  EXPECT_DOUBLE_EQ(automatic.resolvedPenalty(5e-4, 1e6), 1e-12);  // G1 in metres and pascals
  EXPECT_DOUBLE_EQ(loadScene(g1, {P + "0"}, "").capstans.at(0).contact.resolvedPenalty(5e-4, 1e6), 1e-3);
  const auto own = loadScene(g1, {P + "0.14", plain}, "");
  EXPECT_DOUBLE_EQ(own.capstans.at(0).contact.resolvedPenalty(0.5, 1.0), 0.14);
  EXPECT_TRUE(own.warnings.empty());
}

// The solves' eps: at least the floor (1e-2 h / c with the nodal rule), the augmented
// Lagrangian's at most 1e-1 h / c, its automatic 1e-3 at the floor where 1e-3 lies above that.
TEST_F(SceneTest, ContactSolvePenaltyBounds) {
  const std::string g1 = std::string(CAPSTAN_INPUTS_DIR) + "/seed/g1.xml";  // augmented Lagrangian
  const std::string P = "Capstans/capstan/Contact/Penalty=";
  const auto exact = [&](const std::string& eps2) { return loadScene(g1, {P + eps2}, "").capstans.at(0).contact; };
  EXPECT_DOUBLE_EQ(exact("0").solvePenalty(0.5, 1.0, true), 5e-3);       // G1: the floor above 1e-3
  EXPECT_DOUBLE_EQ(exact("0").solvePenalty(0.036, 1.0, true), 1e-3);     // the Hertz ring: 1e-3 itself
  EXPECT_DOUBLE_EQ(exact("0").solvePenalty(5e-4, 1e6, true), 5e-12);     // G1 in metres: the floor
  EXPECT_DOUBLE_EQ(exact("1e-3").solvePenalty(5e-4, 1e6, true), 5e-11);  // 1e-3 written: the cap
  EXPECT_DOUBLE_EQ(exact("10").solvePenalty(0.5, 1.0, true), 5e-2);
  const auto plain = loadScene(g1, {P + "10", "Capstans/capstan/Contact/Method=Penalty"}, "").capstans.at(0).contact;
  EXPECT_DOUBLE_EQ(plain.solvePenalty(0.5, 1.0, true), 10.0);  // its own answer: no cap
  EXPECT_DOUBLE_EQ(plain.solvePenalty(0.5, 1.0, false), 10.0);
}

// Tanh or Arctan finer than 3e-7 of the capstan's surface speed is solved as
// Coulomb, with a warning; at the floor and above, and with no speed to compare
// with, as written.
TEST_F(SceneTest, TinyRegularisationSolvedAsCoulomb) {
  const std::string h1 = std::string(CAPSTAN_INPUTS_DIR) + "/seed/h1.xml";  // 12.5 rad/s x R = 2: 25
  const std::string F = "Capstans/capstan/Friction/";
  using Law = FrictionSettings::Law;
  for (const char* law : {"Tanh", "Arctan"}) {
    const auto tiny = loadScene(h1, {F + "Law=" + law, F + "Regularization=7.4e-6"}, "");
    EXPECT_EQ(tiny.capstans[0].friction.law, Law::Coulomb) << law;
    ASSERT_EQ(tiny.warnings.size(), 1u) << law;
    EXPECT_NE(tiny.warnings[0].find("Capstans/capstan/Friction/Regularization"), std::string::npos) << tiny.warnings[0];
    EXPECT_NE(tiny.warnings[0].find(h1), std::string::npos) << tiny.warnings[0];
    const auto kept = loadScene(h1, {F + "Law=" + law, F + "Regularization=7.6e-6"}, "");
    EXPECT_NE(kept.capstans[0].friction.law, Law::Coulomb) << law;
    EXPECT_TRUE(kept.warnings.empty()) << law;
  }
  // A capstan that neither turns nor moves: no speed to measure the scale against.
  const auto still = loadScene(h1, {F + "Regularization=1e-15", "Capstans/capstan/Angular Velocity=0"}, "");
  EXPECT_EQ(still.capstans[0].friction.law, Law::Tanh);
}

// A named preconditioner that a direct solve never builds is a warning
// naming the file and the parameter; one a Krylov solve builds is not.
TEST_F(SceneTest, PreconditionerUnusedByDirectSolve) {
  const std::string g1 = std::string(CAPSTAN_INPUTS_DIR) + "/seed/g1.xml";
  const auto direct = loadScene(g1, {"Solver/Linear Solver=Direct", "Solver/Preconditioner=ILU"}, "");
  ASSERT_EQ(direct.warnings.size(), 1u);
  EXPECT_NE(direct.warnings[0].find(g1 + ": parameter 'Solver/Preconditioner': ILU is not used: Linear Solver = Direct"),
            std::string::npos)
      << direct.warnings[0];
  EXPECT_TRUE(loadScene(g1, {"Solver/Linear Solver=Direct", "Solver/Preconditioner=None"}, "").warnings.empty());
  EXPECT_TRUE(loadScene(g1, {"Solver/Linear Solver=GMRES", "Solver/Preconditioner=ILU"}, "").warnings.empty());
  // Auto solves G1 (1,575 unknowns, frictionless) by GMRES with the LU
  // preconditioner: a named one replaces it. With friction Auto is direct.
  EXPECT_TRUE(loadScene(g1, {"Solver/Preconditioner=MueLu"}, "").warnings.empty());
  const std::string h1 = std::string(CAPSTAN_INPUTS_DIR) + "/seed/h1.xml";
  const auto autoDirect = loadScene(h1, {"Solver/Preconditioner=MueLu"}, "");
  ASSERT_EQ(autoDirect.warnings.size(), 1u);
  EXPECT_NE(autoDirect.warnings[0].find("MueLu is not used: Linear Solver = Auto solves this scene directly"),
            std::string::npos)
      << autoDirect.warnings[0];
}

// A capstan that can never reach its faces is flagged, conservatively.
TEST_F(SceneTest, UnreachableCapstanWarning) {
  const std::string g1 = std::string(CAPSTAN_INPUTS_DIR) + "/seed/g1.xml";
  const std::string C = "Capstans/capstan/";
  EXPECT_TRUE(loadScene(g1, {}, "").warnings.empty());
  const auto far = loadScene(g1, {C + "Axis Point={3.5, 100, 0}"}, "");
  ASSERT_EQ(far.warnings.size(), 1u);
  EXPECT_NE(far.warnings[0].find("Capstans/capstan"), std::string::npos) << far.warnings[0];
  EXPECT_NE(far.warnings[0].find(g1), std::string::npos) << far.warnings[0];
  // Body 7 x 1.75 x 4: the faces' box grows by 7; ymax at 1.75 + 7 = 8.75, so an
  // axis at y = 10.75 + 1e-6 (R = 2) is out of reach, one at 10.7 is not.
  EXPECT_EQ(loadScene(g1, {C + "Axis Point={3.5, 10.7501, 0}", C + "Velocity={0, 0, 0}"}, "").warnings.size(), 1u);
  EXPECT_TRUE(loadScene(g1, {C + "Axis Point={3.5, 10.7, 0}", C + "Velocity={0, 0, 0}"}, "").warnings.empty());
  // Moving in over the run (5 steps of 1: 50 down) reaches the body.
  EXPECT_TRUE(loadScene(g1, {C + "Axis Point={3.5, 40, 0}", C + "Velocity={0, -10, 0}"}, "").warnings.empty());
  // A Displacement support moving the body also counts: 5 x 2 = 10 of travel.
  EXPECT_TRUE(loadScene(g1, {C + "Axis Point={3.5, 15, 0}", C + "Velocity={0, 0, 0}",
                             "Supports/base/Type=Displacement", "Supports/base/Velocity={0, 2, 0}"}, "")
                  .warnings.empty());
  // A skewed axis far off to the side of the body in x.
  EXPECT_EQ(loadScene(g1, {C + "Axis Point={40, 0, 0}", C + "Axis Direction={0, 1, 1}", C + "Velocity={0, 0, 0}"}, "")
                .warnings.size(), 1u);
}
#endif

}  // namespace

// Linear Solver = Auto by the scene's kind and size (docs/performance.md,
// "Linear solvers"): MUMPS up to 5,000 dofs on a box (40,000 for the
// monolithic pressure loop), 50,000 on an annulus;
// factorised every Newton iteration with friction, kept as GMRES's LU
// preconditioner without; GMRES with MueLu (ILU below 1000 dofs) above.
// Steady rolling: MUMPS likewise up to that size, GMRES + LU above.
TEST(SolverSettings, AutoResolvesByKindAndSize) {
  using S = SolverSettings;
  const S s = S::defaults();
  EXPECT_EQ(s.directSolverMaxDofs, 0);
  auto pick = [&](const S& from, long dofs, bool annulus, bool friction) {
    const S r = from.resolved(dofs, annulus, friction);
    return std::make_pair(r.linearSolver, r.preconditioner);
  };
  EXPECT_EQ(pick(s, 1575, false, false), std::make_pair(S::LinearSolver::GMRES, S::Preconditioner::LU));
  EXPECT_EQ(pick(s, 1920, true, true).first, S::LinearSolver::Direct);
  EXPECT_EQ(pick(s, 5000, false, true).first, S::LinearSolver::Direct);
  EXPECT_EQ(pick(s, 5001, false, true), std::make_pair(S::LinearSolver::GMRES, S::Preconditioner::MueLu));
  // The monolithic loop (no friction) keeps the LU preconditioner up to 40,000 on a box.
  EXPECT_EQ(pick(s, 10179, false, false), std::make_pair(S::LinearSolver::GMRES, S::Preconditioner::LU));
  EXPECT_EQ(pick(s, 31863, false, false), std::make_pair(S::LinearSolver::GMRES, S::Preconditioner::LU));
  EXPECT_EQ(pick(s, 40001, false, false), std::make_pair(S::LinearSolver::GMRES, S::Preconditioner::MueLu));
  S nested = s;
  nested.monolithic = false;
  EXPECT_EQ(pick(nested, 10179, false, false), std::make_pair(S::LinearSolver::GMRES, S::Preconditioner::MueLu));
  EXPECT_EQ(pick(s, 15120, true, false), std::make_pair(S::LinearSolver::GMRES, S::Preconditioner::LU));
  EXPECT_EQ(pick(s, 50001, true, false), std::make_pair(S::LinearSolver::GMRES, S::Preconditioner::MueLu));
  EXPECT_EQ(pick(s, 500, true, false).second, S::Preconditioner::LU);
  // Steady rolling: a factorisation every iteration up to the direct size, a
  // kept one above it, never MueLu (omega's row has no diagonal).
  for (long dofs : {1920L, 50000L}) EXPECT_EQ(s.resolved(dofs, true, true, true).linearSolver, S::LinearSolver::Direct);
  const S big = s.resolved(50001, true, true, true);
  EXPECT_EQ(std::make_pair(big.linearSolver, big.preconditioner), std::make_pair(S::LinearSolver::GMRES, S::Preconditioner::LU));
  EXPECT_TRUE(s.resolved(60000, true, false).gradedRings) << "an annulus' MueLu smooths for graded rings";
  EXPECT_FALSE(s.resolved(60000, false, false).gradedRings);
  EXPECT_TRUE(s.resolved(60000, true, false).resolved(60000, false, false).gradedRings) << "kept when resolved again";
  // A scene's own choices stay; a positive Direct Solver Max Dofs applies to both meshes.
  S own = s;
  own.preconditioner = S::Preconditioner::ILU;
  EXPECT_EQ(pick(own, 1575, false, false), std::make_pair(S::LinearSolver::GMRES, S::Preconditioner::ILU));
  own = s;
  own.linearSolver = S::LinearSolver::Direct;
  EXPECT_EQ(pick(own, 1000000, false, false).first, S::LinearSolver::Direct);
  own = s;
  own.directSolverMaxDofs = 100;
  EXPECT_EQ(pick(own, 1575, true, true), std::make_pair(S::LinearSolver::GMRES, S::Preconditioner::MueLu));
  EXPECT_EQ(pick(own, 500, true, true), std::make_pair(S::LinearSolver::GMRES, S::Preconditioner::ILU));
}

// Pressure Update = Auto by the scene's kind (docs/friction.md, "The multiplier
// loop in rolling"): the saddle-point step but for non-rolling friction scenes,
// and without friction as the monolithic Newton step.
TEST(SolverSettings, PressureUpdateAutoByKind) {
  using P = SolverSettings::PressureUpdate;
  EXPECT_EQ(SolverSettings::defaults(false).pressureUpdate, P::SaddlePoint) << "no friction";
  EXPECT_TRUE(SolverSettings::defaults(false).monolithic) << "no friction";
  EXPECT_TRUE(SolverSettings::defaults(false, false, true).monolithic) << "steady, no friction";
  EXPECT_FALSE(SolverSettings::defaults(true, true).monolithic) << "quasi-static rolling";
  EXPECT_FALSE(SolverSettings::defaults(true, false, true).monolithic) << "steady rolling";
  EXPECT_EQ(SolverSettings::defaults(true).pressureUpdate, P::Anderson) << "friction, no rolling (H1-H5)";
  EXPECT_EQ(SolverSettings::defaults(true, true).pressureUpdate, P::SaddlePoint) << "quasi-static rolling";
  EXPECT_EQ(SolverSettings::defaults(true, false, true).pressureUpdate, P::SaddlePoint) << "steady rolling";
}

// Monolithic steps take no friction (stick, slip and free change under each
// step): asked for with friction, the scene is rejected at its parameter.
TEST(SolverSettings, MonolithicWithFrictionIsBadInput) {
  Teuchos::ParameterList list;
  SolverSettings::declare(list);
  list.set("Pressure Update", std::string("Monolithic"));
  EXPECT_TRUE(SolverSettings::parse(list, ParameterReader{"scene.xml"}, false).monolithic);
  try {
    SolverSettings::parse(list, ParameterReader{"scene.xml"}, true);
    ADD_FAILURE() << "no InputError for Monolithic with friction";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("Solver/Pressure Update"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("scene.xml"), std::string::npos) << e.what();
  }
}

// Max Newton Iterations = 0: 60 for rolling with friction, quasi-static or
// steady (their first solves crawl past 30 and converge), 30 otherwise.
TEST(SolverSettings, MaxNewtonIterationsAutoByKind) {
  EXPECT_EQ(SolverSettings::defaults(false).maxNewtonIterations, 30);
  EXPECT_EQ(SolverSettings::defaults(true).maxNewtonIterations, 30) << "friction, no rolling";
  EXPECT_EQ(SolverSettings::defaults(true, true).maxNewtonIterations, 60) << "quasi-static rolling";
  EXPECT_EQ(SolverSettings::defaults(true, false, true).maxNewtonIterations, 60) << "steady rolling";
  EXPECT_EQ(SolverSettings::defaults(false, false, true).maxNewtonIterations, 30) << "steady, frictionless";
}
