#include "scene.hpp"

#include <Teuchos_ParameterEntryXMLConverterDB.hpp>
#include <Teuchos_StrUtils.hpp>
#include <Teuchos_StringInputSource.hpp>
#include <Teuchos_XMLParameterListHelpers.hpp>
#include <Teuchos_XMLParameterListReader.hpp>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>

#include "errors.hpp"
#include "log.hpp"
#include "mesh.hpp"
#include "parameters.hpp"
#include "rolling.hpp"
#include "vec3.hpp"

namespace capstan {

using Teuchos::Array;
using Teuchos::ParameterList;

namespace {

// Sublists whose children have names chosen by the user: each child is checked
// against this template.
const char* kAnyName = "<any name>";
// Sublists passed through to Trilinos unchanged.
const std::set<std::string> kPassThrough = {"NOX", "Stratimikos", "Belos", "Ifpack2"};
// Tanh and Arctan with a slip speed scale below this fraction of the capstan's surface speed are
// solved as their limit, Coulomb: round-off cannot resolve their sticking points' slip
// (docs/friction.md, "The floor: below 3e-7 of the capstan's speed, the law's limit").
constexpr double kFinestSlipSpeedScale = 3e-7;

Array<double> vec3(double a, double b, double c) { return Teuchos::tuple(a, b, c); }

void solveTinyRegularisationAsCoulomb(CapstanSpec& cs, const std::string& path, Scene& sc) {
  auto& fr = cs.friction;
  if (fr.law != FrictionSettings::Law::Tanh && fr.law != FrictionSettings::Law::Arctan) return;
  const double speed = cs.surfaceSpeed();
  if (!(fr.regularization < kFinestSlipSpeedScale * speed)) return;
  sc.warnings.push_back(sc.file + ": parameter '" + path + "/Friction/Regularization': " +
                        format("%g lies below %g x the capstan's surface speed (%g)", fr.regularization,
                               kFinestSlipSpeedScale, speed) +
                        ", finer than a Newton solve resolves its sticking points: solved as the law's limit, "
                        "Coulomb (stick and slip), within about 1e-6 of its answer");
  fr.law = FrictionSettings::Law::Coulomb;
}

}  // namespace

ParameterList validParameters() {
  ParameterList p("Scene");
  p.set("Title", std::string(""), "Free text, copied to summary.json");
  p.set("Accuracy", std::string("Scene"),
        "Scene (the mesh and tolerances as written) | Draft (the scene's mesh, Newton "
        "tolerance 1e-6: quick look) | Standard (twice the scene's cells in every direction) | "
        "Fine (four times). Solver parameters the scene sets itself win. Measured errors and "
        "costs on G1 and H1: docs/accuracy.md");

  AnalysisSettings::declare(p.sublist("Analysis", false, "What each step solves"));

  auto& mesh = p.sublist("Mesh", false, "The rubber body's mesh");
  mesh.set("Type", std::string("Box"),
           "Box (structured brick mesh; faces xmin xmax ymin ymax zmin zmax) | Annulus (hollow "
           "cylinder along +z: radial x circumferential x axial bricks; faces inner outer zmin zmax)");
  mesh.set("Min", vec3(0, 0, 0), "Box: lower corner {x, y, z}");
  mesh.set("Max", vec3(1, 1, 1), "Box: upper corner {x, y, z}, each above Min");
  mesh.set("Cells", Array<int>(Teuchos::tuple(4, 4, 4)),
           "Box: bricks along x, y, z (each >= 1). Annulus: radial, circumferential (>= 3), axial");
  mesh.set("Center", vec3(0, 0, 0), "Annulus: the axis point at the zmin end (the axis is along +z)");
  mesh.set("Inner Radius", 1.0, "Annulus: inner radius > 0 (the bonded face 'inner')");
  mesh.set("Outer Radius", 2.0, "Annulus: outer radius > Inner Radius");
  mesh.set("Length", 1.0, "Annulus: length along z > 0");
  mesh.set("Outer Cell Ratio", 1.0,
           "Annulus: radial grading, thickness of the outermost cell over the innermost's (> 0; "
           "< 1 makes the cells thinner towards the outer face, where the nip is)");
  mesh.set("Partition", std::string("Auto"),
           "How the elements are split over MPI ranks: Auto (Slabs where each rank's slab is at "
           "least 16 cells thick, METIS otherwise) | METIS (k-way on the dual graph, fewest faces "
           "cut) | Slabs (equal runs of the cells' numbering: slabs across z for a Box, along the "
           "axis for an Annulus; on G1 8x, 2 ranks take the Krylov iterations of 1 rank: "
           "docs/performance.md, The 2-rank speed-up in rounds)");
  mesh.set("Fine Sector", vec3(0, 0, 0),
           "Annulus: {centre angle, width (degrees, from +x towards +y), fraction of the "
           "circumferential cells placed in it}: a finer sector where the nip is. Width 0: uniform");

  auto& mat = p.sublist("Material", false, "Rubber (formulation.md §1)");
  mat.set("Model", std::string("Incompressible Neo-Hookean"),
          "Incompressible Neo-Hookean: sigma = -p I + 2c (B - I), Q1P0 bricks");
  mat.set("c", 1.0, "Material constant c > 0 (shear modulus 2c)");
  mat.set("Pressure Penalty", 0.0,
          "eps1 >= 0: pressure penalty of the condensed Newton step. The converged state "
          "(v_e = V_e) does not depend on it; in the linear solves eps1 x c is held between "
          "Solver/Minimum Solve Penalty and 1e-1; 0 = automatic, at that minimum, in any units "
          "(see docs/numerics.md)");

  auto& loads = p.sublist("Loads", false, "Loads on the body besides its supports and capstans");
  loads.set("Body Force", vec3(0, 0, 0),
            "Dead load {bx, by, bz} per unit reference volume (e.g. rho g), reached at the end "
            "of the run: b t / (Steps x Step Size). Zero: no body-force kernel runs");

  auto& sup = p.sublist("Supports", false, "Boundary supports, one sublist per support, any name");
  SupportSpec::declare(sup.sublist(kAnyName, false, "A support"));

  auto& caps = p.sublist("Capstans", false, "Rigid cylinders (formulation.md §2), one sublist each, any name");
  auto& c = caps.sublist(kAnyName, false, "A capstan");
  c.set("Radius", 1.0, "R > 0");
  c.set("Axis Point", vec3(0, 0, 0), "A point a of the axis at t = 0");
  c.set("Axis Direction", vec3(0, 0, 1), "Axis direction beta (non-zero)");
  c.set("Velocity", vec3(0, 0, 0), "Translation of the axis per unit time");
  c.set("Angular Velocity", 0.0, "Spin about the axis, rad per unit time, right-hand rule");
  c.set("Contact Faces", std::string(""), "Candidate contact faces, names separated by spaces or commas");
  ContactSettings::declare(c.sublist("Contact", false, "Normal contact"));
  FrictionSettings::declare(c.sublist("Friction", false, "Friction between body and capstan (formulation.md §3)"));

  auto& time = p.sublist("Time", false, "Quasi-static load steps t_n = n dt");
  time.set("Steps", 1, "Number of steps (>= 1)");
  time.set("Step Size", 1.0, "dt > 0");

  SolverSettings::declare(p.sublist("Solver", false, "Nonlinear and linear solvers"));

  auto& out = p.sublist("Output", false, "Where and what to write");
  out.set("Directory", std::string("out"), "Output directory (created if missing)");
  out.set("Write Fields", true, "Write fields.h5 + fields.xmf");
  out.set("Checkpoint Every", 0,
          "Write a checkpoint (Directory/checkpoint/) after every N-th converged step, for "
          "`capstan run SCENE --restart DIR`; only the newest is kept. 0 = never");
  return p;
}

namespace {

// The parameter reader plus the structural check of the whole scene.
struct Validator : ParameterReader {

  // Unknown names and wrong types; fills in defaults. An int given where a
  // double is expected is accepted and converted.
  void check(ParameterList& user, const ParameterList& valid, const std::string& path) const {
    const bool anyName = valid.isSublist(kAnyName);
    for (auto it = user.begin(); it != user.end(); ++it) {
      const std::string name = user.name(it);
      const std::string here = path.empty() ? name : path + "/" + name;
      const auto& entry = user.entry(it);
      if (anyName) {
        if (!entry.isList()) fail(here, "expected a sublist (one per object)");
        check(user.sublist(name), valid.sublist(kAnyName), here);
        continue;
      }
      if (!valid.isParameter(name)) fail(here, "unknown parameter (see `capstan params`)");
      const auto& ventry = valid.getEntry(name);
      if (ventry.isList()) {
        if (!entry.isList()) fail(here, "expected a sublist");
        if (kPassThrough.count(name)) continue;
        check(user.sublist(name), valid.sublist(name), here);
        continue;
      }
      if (entry.isList()) fail(here, "expected a parameter, got a sublist");
      const auto& va = ventry.getAny(false);
      const auto& ua = entry.getAny(false);
      if (va.type() == ua.type()) continue;
      if (va.type() == typeid(double) && ua.type() == typeid(int)) {
        user.set(name, double(Teuchos::any_cast<int>(ua)));
        continue;
      }
      if (va.type() == typeid(Array<double>) && ua.type() == typeid(Array<int>)) {
        const auto& a = Teuchos::any_cast<Array<int>>(ua);
        user.set(name, Array<double>(a.begin(), a.end()));
        continue;
      }
      fail(here, "expected type " + va.typeName() + ", got " + ua.typeName());
    }
    if (anyName) return;
    for (auto it = valid.begin(); it != valid.end(); ++it) {
      const std::string name = valid.name(it);
      if (user.isParameter(name)) continue;
      if (valid.entry(it).isList())
        user.sublist(name) = valid.sublist(name).isSublist(kAnyName) ? ParameterList(name) : valid.sublist(name);
      else
        user.setEntry(name, valid.entry(it));
    }
    // Defaults inside sublists the user gave only partly, and inside named objects.
    for (auto it = valid.begin(); it != valid.end(); ++it) {
      const std::string name = valid.name(it);
      if (!valid.entry(it).isList() || kPassThrough.count(name)) continue;
      const auto& vsub = valid.sublist(name);
      const std::string here = path.empty() ? name : path + "/" + name;
      if (vsub.isSublist(kAnyName)) {
        auto& usub = user.sublist(name);
        for (auto jt = usub.begin(); jt != usub.end(); ++jt)
          check(usub.sublist(usub.name(jt)), vsub.sublist(kAnyName), here + "/" + usub.name(jt));
      } else {
        check(user.sublist(name), vsub, here);
      }
    }
  }
};

// Strict readings of numbers as written in the scene or in --set. Teuchos reads
// them with a stream and keeps whatever prefix parses ("5.5" as the int 5,
// "abc" or "nan" as 0.0), so every number is checked here first.
std::string trimmed(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r\n"), b = s.find_last_not_of(" \t\r\n");
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}


// A finite double written in decimal (no hex, inf or nan), or false.
bool readDouble(const std::string& text, double& x) {
  const std::string t = trimmed(text);
  if (t.empty() || t.find_first_not_of("0123456789+-.eE") != std::string::npos) return false;
  errno = 0;
  char* end = nullptr;
  x = std::strtod(t.c_str(), &end);
  return end == t.c_str() + t.size() && errno != ERANGE && std::isfinite(x);
}

// As the scene files spell a bool (Teuchos' XML reader: true/false, yes/no),
// whatever the case, and 1/0; anything else is bad input, not false.
bool readBool(const std::string& text) {
  std::string t = text;
  for (auto& c : t) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (t == "true" || t == "yes" || t == "1") return true;
  if (t == "false" || t == "no" || t == "0") return false;
  throw std::invalid_argument("not a bool");
}

bool readInt(const std::string& text, int& x) {
  const std::string t = trimmed(text);
  if (t.empty() || t.find_first_not_of("0123456789+-") != std::string::npos) return false;
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(t.c_str(), &end, 10);
  if (end != t.c_str() + t.size() || errno == ERANGE || v < INT_MIN || v > INT_MAX) return false;
  x = int(v);
  return true;
}

// "{a, b, c}" (or "{}") with every element read by readDouble / readInt.
template <class T>
bool readArray(const std::string& text, Array<T>& out) {
  const std::string t = trimmed(text);
  if (t.size() < 2 || t.front() != '{' || t.back() != '}') return false;
  out.clear();
  const std::string inner = t.substr(1, t.size() - 2);
  if (trimmed(inner).empty()) return true;
  std::stringstream ss(inner);
  for (std::string item; std::getline(ss, item, ',');) {
    T x;
    bool ok;
    if constexpr (std::is_same_v<T, int>) ok = readInt(item, x);
    else ok = readDouble(item, x);
    if (!ok) return false;
    out.push_back(x);
  }
  return inner.back() != ',';  // "{1, 2,}": a missing element
}

// Why a number parameter's text does not read as its type, or "".
std::string numberError(const std::string& type, const std::string& value) {
  double d;
  int i;
  Array<double> ad;
  Array<int> ai;
  if (type == "double" && !readDouble(value, d))
    return "'" + value + "' is not a finite number (type double)";
  if (type == "int" && !readInt(value, i))
    return "'" + value + "' is not an integer in the range of int (type int)";
  if (type == "Array(double)" && !readArray(value, ad))
    return "'" + value + "' is not a list {x, y, ...} of finite numbers (type Array(double))";
  if (type == "Array(int)" && !readArray(value, ai))
    return "'" + value + "' is not a list {i, j, ...} of integers (type Array(int))";
  return "";
}

// Deepest element nesting of an XML text (comments, processing instructions,
// declarations and quoted attribute values skipped). The Teuchos reader
// recurses per level and a deep enough file overflows the stack, so depth is
// checked on the raw text first.
int nestingDepth(const std::string& x) {
  int depth = 0, deepest = 0;
  size_t i = 0;
  auto skipPast = [&](const char* end) {
    const size_t p = x.find(end, i);
    i = p == std::string::npos ? x.size() : p + std::strlen(end);
  };
  while ((i = x.find('<', i)) != std::string::npos) {
    if (x.compare(i, 4, "<!--") == 0) skipPast("-->");
    else if (x.compare(i, 9, "<![CDATA[") == 0) skipPast("]]>");
    else if (x.compare(i, 2, "<?") == 0) skipPast("?>");
    else if (x.compare(i, 2, "<!") == 0) skipPast(">");
    else if (x.compare(i, 2, "</") == 0) {
      --depth;
      skipPast(">");
    } else {
      char quote = 0;
      size_t j = i + 1;
      for (; j < x.size(); ++j) {
        if (quote) {
          if (x[j] == quote) quote = 0;
        } else if (x[j] == '"' || x[j] == '\'') {
          quote = x[j];
        } else if (x[j] == '>') {
          break;
        }
      }
      if (j >= x.size() || x[j - 1] != '/') deepest = std::max(deepest, ++depth);
      i = j + 1;
    }
  }
  return deepest;
}

// The scene's XML elements before Teuchos converts them: only ParameterList and
// Parameter, each with a name (sublists may be unnamed only at the root), no
// name twice in one list, and numbers that read exactly as their type.
void checkXml(const Teuchos::XMLObject& list, const std::string& path, const Validator& v) {
  std::set<std::string> names;
  for (int i = 0; i < list.numChildren(); ++i) {
    const auto& child = list.getChild(i);
    const std::string& tag = child.getTag();
    // Teuchos' writer ends every list it writes (capstan validate's) with one.
    if (tag == "Validators" && child.numChildren() == 0 && path.empty()) continue;
    if (tag != "ParameterList" && tag != "Parameter")
      v.fail(path, "unknown XML element <" + tag + "> (a scene has ParameterList and Parameter elements)");
    if (!child.hasAttribute("name"))
      v.fail(path, "a <" + tag + "> without a name attribute" + (path.empty() ? " at the top level" : ""));
    const std::string name = child.getAttribute("name");
    const std::string here = path.empty() ? name : path + "/" + name;
    if (!names.insert(name).second) v.fail(here, "given twice");
    if (tag == "ParameterList") {
      checkXml(child, here, v);
      continue;
    }
    if (!child.hasAttribute("type")) v.fail(here, "no type attribute");
    if (!child.hasAttribute("value")) v.fail(here, "no value attribute");
    const std::string error = numberError(child.getAttribute("type"), child.getAttribute("value"));
    if (!error.empty()) v.fail(here, error);
    try {  // what Teuchos makes of it (unknown types, bad bools, ...), with the path
      Teuchos::ParameterEntryXMLConverterDB::convertXML(child);
    } catch (const std::exception& e) {
      v.fail(here, trilinosMessage(e.what()));
    }
  }
}

Teuchos::RCP<ParameterList> readXml(const std::string& content, const Validator& v) {
  constexpr int kMaxDepth = 64;
  if (nestingDepth(content) > kMaxDepth)
    v.fail("", "malformed scene XML: elements nested deeper than " + std::to_string(kMaxDepth) + " levels");
  Teuchos::XMLObject xml;
  try {
    xml = Teuchos::StringInputSource(content).getObject();
  } catch (const std::exception& e) {
    v.fail("", "malformed scene XML: " + trilinosMessage(e.what()));
  }
  if (xml.isEmpty() || xml.getTag() != "ParameterList")
    v.fail("", std::string("malformed scene XML: the root element must be <ParameterList>") +
                   (xml.isEmpty() ? "" : ", not <" + xml.getTag() + ">"));
  checkXml(xml, "", v);
  auto user = Teuchos::rcp(new ParameterList);
  try {
    Teuchos::XMLParameterListReader reader;
    reader.setAllowsDuplicateSublists(false);
    user->setParameters(reader.toParameterList(xml));
  } catch (const std::exception& e) {
    v.fail("", "malformed scene XML: " + trilinosMessage(e.what()));
  }
  return user;
}

// Golden-section minimum of a convex function on [lo, hi].
template <class F>
double convexMinimum(F f, double lo, double hi) {
  const double g = 0.5 * (std::sqrt(5.0) - 1);
  double a = lo, b = hi, c = b - g * (b - a), d = a + g * (b - a), fc = f(c), fd = f(d);
  for (int it = 0; it < 100 && b - a > 1e-12 * (std::fabs(a) + std::fabs(b) + 1e-300); ++it) {
    if (fc < fd) {
      b = d, d = c, fd = fc, c = b - g * (b - a), fc = f(c);
    } else {
      a = c, c = d, fc = fd, d = a + g * (b - a), fd = f(d);
    }
  }
  return std::min({f(lo), f(hi), fc, fd});
}

// A capstan that can never touch its contact faces is most likely a typo in Axis Point or Radius.
// Flagged only if the faces' box, enlarged by the body's extent and the supports' travel, stays
// farther than Radius from the axis over its whole travel (a distance convex in t).
void warnUnreachable(Scene& sc, const CapstanSpec& c) {
  const auto& m = sc.mesh;
  const double T = sc.steps * sc.stepSize;
  double size = 0, travel = 0;
  for (int i = 0; i < 3; ++i) size = std::max(size, m.max[i] - m.min[i]);
  for (const auto& s : sc.supports)
    if (s.type == SupportSpec::Type::Displacement) {
      double v2 = 0;
      for (int i = 0; i < 3; ++i) v2 += s.components[i] ? s.velocity[i] * s.velocity[i] : 0.0;
      travel = std::max(travel, std::sqrt(v2) * T);
    }
  std::array<double, 3> lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (const auto& face : c.contactFaces) {
    // A box face is one side of the box; any other (annulus) face: the whole box.
    const bool boxFace = m.type == MeshSpec::Type::Box;
    const int axis = boxFace ? face[0] - 'x' : -1;
    const bool isMax = face.substr(1) == "max";
    for (int i = 0; i < 3; ++i) {
      const double a = i == axis ? (isMax ? m.max[i] : m.min[i]) : m.min[i];
      const double b = i == axis ? a : m.max[i];
      lo[i] = std::min(lo[i], a), hi[i] = std::max(hi[i], b);
    }
  }
  const double grow = size + travel;
  for (int i = 0; i < 3; ++i) lo[i] -= grow, hi[i] += grow;
  const Vec3 b = unit(c.axisDirection);
  auto pointToBox = [&](const std::array<double, 3>& p) {
    double d2 = 0;
    for (int i = 0; i < 3; ++i) {
      const double e = std::max({lo[i] - p[i], 0.0, p[i] - hi[i]});
      d2 += e * e;
    }
    return std::sqrt(d2);
  };
  auto lineToBox = [&](double t) {
    std::array<double, 3> a;
    for (int i = 0; i < 3; ++i) a[i] = c.axisPoint[i] + c.velocity[i] * t;
    // The nearest point of the line lies between the projections of the box's corners.
    double s0 = 1e300, s1 = -1e300;
    for (int k = 0; k < 8; ++k) {
      double s = 0;
      for (int i = 0; i < 3; ++i) s += (((k >> i) & 1 ? hi[i] : lo[i]) - a[i]) * b[i];
      s0 = std::min(s0, s), s1 = std::max(s1, s);
    }
    return convexMinimum(
        [&](double s) {
          return pointToBox({a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]});
        },
        s0, s1);
  };
  const double closest = convexMinimum(lineToBox, 0.0, T);
  if (closest > c.radius) {
    std::string faces;
    for (const auto& f : c.contactFaces) faces += (faces.empty() ? "" : " ") + f;
    sc.warnings.push_back(sc.file + ": parameter 'Capstans/" + c.name + "': the capstan can never touch its "
                          "Contact Faces (" + faces + "): over the whole run its axis stays " +
                          brief(closest + grow) + " or more from them, beyond its Radius " +
                          shortest(c.radius) + " plus the body's size and support travel (" +
                          brief(grow) + "); check Axis Point, Velocity and Radius");
  }
}

// Walks PATH (sublists separated by '/') and sets VALUE with the parameter's type,
// taken from the scene or from the valid list.
void applySet(ParameterList& scene, const ParameterList& valid, const std::string& file,
              const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError(file + ": --set '" + assignment + "': expected PATH=VALUE");
  const std::string path = assignment.substr(0, eq), value = assignment.substr(eq + 1);
  std::vector<std::string> parts;
  std::stringstream ss(path);
  for (std::string part; std::getline(ss, part, '/');) parts.push_back(part);
  ParameterList* list = &scene;
  const ParameterList* vlist = &valid;
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    list = &list->sublist(parts[i]);
    if (vlist) {
      if (vlist->isSublist(parts[i])) vlist = &vlist->sublist(parts[i]);
      else if (vlist->isSublist(kAnyName)) vlist = &vlist->sublist(kAnyName);
      else vlist = nullptr;
    }
  }
  const std::string& name = parts.back();
  const Teuchos::ParameterEntry* typed = list->isParameter(name) ? &list->getEntry(name)
                                         : (vlist && vlist->isParameter(name)) ? &vlist->getEntry(name)
                                                                               : nullptr;
  bool passedThrough = false;  // inside a Trilinos sublist: typed by how VALUE reads
  for (size_t i = 0; i + 1 < parts.size(); ++i) passedThrough = passedThrough || kPassThrough.count(parts[i]) > 0;
  if (!typed && passedThrough) {
    int i;
    double d;
    const std::string word = trimmed(value);
    if (readInt(value, i)) list->set(name, i);
    else if (readDouble(value, d)) list->set(name, d);
    else if (word == "true" || word == "false") list->set(name, word == "true");
    else list->set(name, value);
    return;
  }
  if (!typed) throw InputError(file + ": --set: parameter '" + path + "': unknown parameter");
  const auto& t = typed->getAny(false).type();
  try {
    auto number = [&](auto parsed) {
      bool ok;
      if constexpr (std::is_same_v<decltype(parsed), int>) ok = readInt(value, parsed);
      else ok = readDouble(value, parsed);
      if (!ok) throw std::invalid_argument("not a number");
      return parsed;
    };
    if (t == typeid(double)) list->set(name, number(0.0));
    else if (t == typeid(int)) list->set(name, number(0));
    else if (t == typeid(bool)) list->set(name, readBool(value));
    else if (t == typeid(std::string)) list->set(name, value);
    else if (t == typeid(Array<double>) || t == typeid(Array<int>)) {
      Array<double> ad;
      Array<int> ai;
      if (t == typeid(Array<int>) ? !readArray(value, ai) : !readArray(value, ad))
        throw std::invalid_argument("not a list");
      if (t == typeid(Array<int>)) list->set(name, ai);
      else list->set(name, ad);
    } else throw std::invalid_argument("type not settable");
  } catch (const std::exception& e) {
    throw InputError(file + ": --set: parameter '" + path + "': cannot read '" + value + "' as " +
                     typed->getAny(false).typeName());
  }
}

std::vector<std::string> splitNames(const std::string& s) {
  std::vector<std::string> names;
  std::string cur;
  for (char ch : s + " ") {
    if (ch == ' ' || ch == ',') {
      if (!cur.empty()) names.push_back(cur);
      cur.clear();
    } else {
      cur += ch;
    }
  }
  return names;
}

// Accuracy presets (docs/accuracy.md, "Accuracy presets"): the mesh sets the error, so a preset
// scales Mesh/Cells; Draft keeps the mesh and loosens the Newton tolerance. Applied before defaults
// are filled in, so solver parameters the scene (or --set) names win.
void applyAccuracyPreset(ParameterList& user, const Validator& v) {
  if (!user.isType<std::string>("Accuracy")) return;  // absent, or a type error check() reports
  const std::string preset = user.get<std::string>("Accuracy");
  int refine = 1;
  if (preset == "Draft") {
    auto& solver = user.sublist("Solver");
    if (!solver.isParameter("Newton Relative Tolerance")) solver.set("Newton Relative Tolerance", 1e-6);
  } else if (preset == "Standard") {
    refine = 2;
  } else if (preset == "Fine") {
    refine = 4;
  } else if (preset != "Scene") {
    v.fail("Accuracy", "'" + preset + "' is not an accuracy preset (Scene, Draft, Standard, Fine)");
  }
  if (refine != 1 && user.isSublist("Mesh") && user.sublist("Mesh").isType<Array<int>>("Cells")) {
    Array<int> cells = user.sublist("Mesh").get<Array<int>>("Cells");
    for (int& n : cells) {
      if (n > 1000000) v.fail("Accuracy", "'" + preset + "' would refine Mesh/Cells beyond 1e6 per direction");
      n *= refine;
    }
    user.sublist("Mesh").set("Cells", cells);
  }
}

}  // namespace

// Non-zero magnitudes capstan computes with (the shipped scenes and tests use 1e-15 to 1e3): far
// beyond, the kernels' products overflow or vanish (c = 1e300 left NaN in the outputs). Directions
// are scaled to unit length first, whatever their size.
constexpr double kSmallest = 1e-25, kLargest = 1e25;

static void rejectMagnitudesOutOfRange(const ParameterList& list, const std::string& path, const Validator& v) {
  for (auto it = list.begin(); it != list.end(); ++it) {
    const std::string name = list.name(it), here = path.empty() ? name : path + "/" + name;
    const auto& entry = list.entry(it);
    if (entry.isList()) {
      if (!kPassThrough.count(name)) rejectMagnitudesOutOfRange(list.sublist(name), here, v);
      continue;
    }
    if (name == "Axis Direction") continue;
    std::vector<double> values;
    if (entry.isType<double>()) values.push_back(Teuchos::getValue<double>(entry));
    else if (entry.isType<Array<double>>()) {
      const auto& a = Teuchos::getValue<Array<double>>(entry);
      values.assign(a.begin(), a.end());
    }
    for (double x : values)
      if (std::isfinite(x) && x != 0 && !(std::fabs(x) >= kSmallest && std::fabs(x) <= kLargest))
        v.fail(here, shortest(x) + " is outside the magnitudes capstan computes with (0, or " + shortest(kSmallest) +
                         " to " + shortest(kLargest) + " in size)");
  }
}

// A cell far thinner in one direction than in another (a Length of 1e-20 on
// a unit ring, an Outer Cell Ratio of 1e-20, a Fine Sector of 1e-20 degrees)
// makes its Jacobian singular to round-off: the stresses came out NaN.
constexpr double kFlattestCell = 1e-6;

static void rejectFlatCells(const MeshSpec& m, const Validator& v) {
  double lo = 1e300, hi = 0;  // the smallest and largest cell edge
  auto take = [&](double h) { lo = std::min(lo, h), hi = std::max(hi, h); };
  std::string which = "Mesh/Cells";
  if (m.type == MeshSpec::Type::Box) {
    for (int d = 0; d < 3; ++d) take((m.max[d] - m.min[d]) / m.cells[d]);
  } else {
    // Radial thicknesses t0 q^k (q^(n-1) = Outer Cell Ratio), the ring cells'
    // arcs on the inner and outer faces, the axial length.
    const int nr = m.cells[0];
    const double q = nr > 1 ? std::pow(m.outerCellRatio, 1.0 / (nr - 1)) : 1.0;
    const double sum = std::fabs(q - 1) < 1e-12 ? nr : (std::pow(q, nr) - 1) / (q - 1);  // sum of q^k, k < nr
    const double t0 = (m.outerRadius - m.innerRadius) / sum;
    take(t0), take(t0 * std::pow(q, nr - 1));
    const double degree = 3.14159265358979323846 / 180;
    take(m.innerRadius * degree * AnnulusGenerator::narrowestRingCellDegrees(m.cells[1], m.fineSector));
    take(m.outerRadius * degree * AnnulusGenerator::widestRingCellDegrees(m.cells[1], m.fineSector));
    take(m.length / m.cells[2]);
    which = "Mesh";
  }
  if (!(lo >= kFlattestCell * hi))
    v.fail(which, "cells " + brief(hi / lo) + " times longer in one direction than in another (at most " +
                      shortest(1 / kFlattestCell) + "): check the sizes, Cells" +
                      (m.type == MeshSpec::Type::Box ? std::string() : ", Outer Cell Ratio and Fine Sector"));
}

// The mesh parameters that a mesh of `type` does not read (the other type's).
static const std::vector<std::string>& otherMeshTypeParameters(const std::string& type) {
  static const std::vector<std::string> boxOnly = {"Min", "Max"}, none;
  static const std::vector<std::string> annulusOnly = {"Center", "Inner Radius", "Outer Radius", "Length",
                                                       "Outer Cell Ratio", "Fine Sector"};
  return type == "Annulus" ? boxOnly : type == "Box" ? annulusOnly : none;
}

// A mesh parameter of the other mesh type would be silently ignored: most likely
// a forgotten or misspelled Mesh/Type, so it is an error. Checked on the user's
// list, before defaults fill in every parameter of both types.
static void rejectOtherMeshTypeParameters(const ParameterList& user, const Validator& v) {
  if (!user.isSublist("Mesh")) return;
  const auto& mesh = user.sublist("Mesh");
  const std::string type = mesh.isType<std::string>("Type") ? mesh.get<std::string>("Type") : "Box";
  for (const auto& name : otherMeshTypeParameters(type))
    if (mesh.isParameter(name))
      v.fail("Mesh/" + name, "is not a parameter of Mesh/Type = " + type + " (it belongs to " +
                                 (type == "Box" ? "Annulus" : "Box") + ")");
}

// Two supports that prescribe the same component of one face contradict each
// other (one would silently win): Fixed, Roller, Displacement and Rigid Core
// prescribe their components; a Foundation only adds a spring.
static void rejectSupportsHoldingOneComponentTwice(const std::vector<SupportSpec>& supports, const Validator& v) {
  using T = SupportSpec::Type;
  for (size_t j = 0; j < supports.size(); ++j)
    for (size_t i = 0; i < j; ++i) {
      const auto &a = supports[i], &b = supports[j];
      if (a.face != b.face || a.type == T::Foundation || b.type == T::Foundation) continue;
      for (int c = 0; c < 3; ++c)
        if (a.components[c] && b.components[c])
          v.fail("Supports/" + b.name + "/Face",
                 "face '" + b.face + "' is already held along " + char('x' + c) + " by Supports/" + a.name + " (" +
                     nameOf(a.type, SupportSpec::types) + "): two supports cannot prescribe one component");
    }
}

// A free rigid-core component that nothing can ever hold makes every tangent
// singular: an input error rather than a failed solve. Capstan contact pushes
// along directions normal to the capstan's axis, friction along the surface;
// a rotation is held only by friction.
static void rejectSingularCores(const Scene& sc, const Validator& v) {
  for (const auto& s : sc.supports) {
    if (!s.isCore()) continue;
    const std::string path = "Supports/" + s.name;
    if (s.rotation == SupportSpec::Rotation::Free) {
      bool friction = false;
      for (const auto& c : sc.capstans) friction |= c.friction.grips();
      if (!friction)
        v.fail(path + "/Rotation", "Free, but no capstan has friction (Friction/Law and Coefficient > 0): "
                                   "nothing can hold the core's rotation (use Fixed or Prescribed, or add friction)");
    }
    for (int i = 0; i < 3; ++i) {
      if (!s.freeTranslation[i]) continue;
      bool held = false;
      for (const auto& c : sc.capstans) {
        const auto& b = c.axisDirection;
        held |= std::fabs(b[i]) / norm(b) < 1 - 1e-12;  // the capstan's normals have a component along i
      }
      if (!held)
        v.fail(path + "/Free Translation",
               std::string("the core is free along ") + char('x' + i) +
                   ", but no capstan can push it along " + char('x' + i) +
                   (sc.capstans.empty() ? " (the scene has no capstans)" : " (every capstan's axis is along it)") +
                   ": nothing holds it; hold that component or add a capstan");
    }
  }
}

const std::vector<std::pair<const char*, MeshSpec::Type>> MeshSpec::types = {{"Box", Type::Box},
                                                                              {"Annulus", Type::Annulus}};

std::vector<std::string> MeshSpec::faceNames() const {
  if (type == Type::Annulus) return {"inner", "outer", "zmin", "zmax"};
  return {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};
}

Scene loadScene(const std::string& file, const std::vector<std::string>& sets,
                const std::string& outputOverride) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) throw InputError(file + ": a directory, not a scene file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file + ": cannot open the scene file");
  std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(file + ": cannot read the scene file");
  return parseScene(content, file, sets, outputOverride);
}

namespace {
// The values alone: Teuchos writes a list's validators (the defaults carry
// them) as a <Validators> block, which no scene may hold.
ParameterList valuesOnly(const ParameterList& list) {
  ParameterList out(list.name());
  for (auto it = list.begin(); it != list.end(); ++it) {
    const auto& name = list.name(it);
    const auto& entry = list.entry(it);
    if (entry.isList()) out.set(name, valuesOnly(list.sublist(name)));
    else out.setEntry(name, Teuchos::ParameterEntry(entry.getAny(), entry.isDefault(), false, entry.docString()));
  }
  return out;
}
}  // namespace

ParameterList printableScene(const Scene& scene) {
  ParameterList p = valuesOnly(scene.resolved);
  p.setName("Scene");
  p.set("Accuracy", std::string("Scene"));  // the preset's cells and tolerances are in the values already
  auto& mesh = p.sublist("Mesh");
  for (const auto& name : otherMeshTypeParameters(mesh.get<std::string>("Type"))) mesh.remove(name);
  if (p.isSublist("Supports")) {
    auto& supports = p.sublist("Supports");
    for (auto it = supports.begin(); it != supports.end(); ++it) {
      auto& s = supports.sublist(supports.name(it));
      const std::string type = s.get<std::string>("Type");
      std::vector<std::string> unread;
      for (auto jt = s.begin(); jt != s.end(); ++jt)
        if (!SupportSpec::readBy(s.name(jt), type)) unread.push_back(s.name(jt));
      for (const auto& name : unread) s.remove(name);
    }
  }
  return p;
}

Scene parseScene(const std::string& content, const std::string& file, const std::vector<std::string>& sets,
                 const std::string& outputOverride) {
  Validator v{file};
  // A UTF-8 byte-order mark before the declaration is well-formed XML.
  if (content.rfind("\xEF\xBB\xBF", 0) == 0) return parseScene(content.substr(3), file, sets, outputOverride);
  if (content.find_first_not_of(" \t\r\n") == std::string::npos)
    throw InputError(file + ": the scene file is empty");
  for (unsigned char ch : content)
    if (ch == 0 || (ch < 32 && ch != '\n' && ch != '\r' && ch != '\t'))
      throw InputError(file + ": not a text XML file (binary data)");
  Teuchos::RCP<ParameterList> user = readXml(content, v);
  const ParameterList valid = validParameters();
  for (const auto& s : sets) applySet(*user, valid, file, s);
  if (!outputOverride.empty()) user->sublist("Output").set("Directory", outputOverride);
  applyAccuracyPreset(*user, v);
  rejectOtherMeshTypeParameters(*user, v);
  if (user->isSublist("Supports")) SupportSpec::rejectParametersOfOtherTypes(user->sublist("Supports"), v);
  v.check(*user, valid, "");
  rejectMagnitudesOutOfRange(*user, "", v);

  Scene sc;
  sc.file = file;
  sc.resolved = *user;
  const auto& P = sc.resolved;
  sc.title = P.get<std::string>("Title");
  sc.analysis = AnalysisSettings::parse(P.sublist("Analysis"), v);

  const auto& mesh = P.sublist("Mesh");
  sc.mesh.type = v.choice(mesh, "Mesh", "Type", MeshSpec::types);
  sc.mesh.partition = mesh.get<std::string>("Partition");
  v.choice(mesh, "Mesh", "Partition", std::vector<std::pair<const char*, bool>>{{"Auto", 1}, {"METIS", 1}, {"Slabs", 1}});
  sc.mesh.cells = v.three<int>(mesh, "Mesh", "Cells");
  for (int d = 0; d < 3; ++d)
    if (sc.mesh.cells[d] < 1) v.fail("Mesh/Cells", "each count must be >= 1");
  double nodes = 0;
  if (sc.mesh.type == MeshSpec::Type::Box) {
    sc.mesh.min = v.three<double>(mesh, "Mesh", "Min");
    sc.mesh.max = v.three<double>(mesh, "Mesh", "Max");
    for (int d = 0; d < 3; ++d)
      if (!(sc.mesh.max[d] > sc.mesh.min[d]))
        v.fail("Mesh/Max", "each component must exceed Mesh/Min (zero or negative size)");
    nodes = double(sc.mesh.cells[0] + 1.0) * (sc.mesh.cells[1] + 1.0) * (sc.mesh.cells[2] + 1.0);
  } else {
    auto& m = sc.mesh;
    m.center = v.three<double>(mesh, "Mesh", "Center");
    for (double x : m.center)
      if (!std::isfinite(x)) v.fail("Mesh/Center", "must be finite numbers");
    m.innerRadius = v.positive(mesh, "Mesh", "Inner Radius");
    m.outerRadius = v.positive(mesh, "Mesh", "Outer Radius");
    m.length = v.positive(mesh, "Mesh", "Length");
    if (!(m.outerRadius > m.innerRadius)) v.fail("Mesh/Outer Radius", "must exceed Mesh/Inner Radius");
    if (m.cells[1] < 3) v.fail("Mesh/Cells", "an annulus needs at least 3 circumferential cells");
    m.outerCellRatio = v.positive(mesh, "Mesh", "Outer Cell Ratio");
    m.fineSector = v.three<double>(mesh, "Mesh", "Fine Sector");
    const auto& fs = m.fineSector;
    if (!std::isfinite(fs[0]) || !(fs[1] >= 0 && fs[1] < 360))
      v.fail("Mesh/Fine Sector", "the centre must be finite and the width in [0, 360) degrees");
    // The centre modulo a turn: at 1e24 degrees the cells' angles rounded to one
    // value (flat cells, NaN stresses).
    m.fineSector[0] = std::remainder(fs[0], 360.0);
    if (fs[1] > 0 && !(fs[2] > 0 && fs[2] < 1))
      v.fail("Mesh/Fine Sector", "the fraction of cells in the sector must be in (0, 1)");
    // A straight-sided cell spanning half the ring or more turns inside out.
    if (m.cells[1] >= 3) {
      const double widest = AnnulusGenerator::widestRingCellDegrees(m.cells[1], fs);
      if (!(widest < 180))
        v.fail("Mesh/Cells", "a ring cell spans " + std::to_string(std::lround(widest)) + " degrees: " +
                                 std::to_string(m.cells[1]) +
                                 " circumferential cells are too few for Mesh/Fine Sector (every cell must span "
                                 "less than 180)");
    }
    m.min = {m.center[0] - m.outerRadius, m.center[1] - m.outerRadius, m.center[2]};
    m.max = {m.center[0] + m.outerRadius, m.center[1] + m.outerRadius, m.center[2] + m.length};
    nodes = double(m.cells[0] + 1.0) * m.cells[1] * (m.cells[2] + 1.0);
  }
  // Local dof ids are ints: 3 x nodes must stay below 2^31.
  if (3 * nodes > double(INT_MAX))
    v.fail("Mesh/Cells", "too many cells: " + shortest(nodes) + " nodes, capstan indexes at most 2^31 / 3");
  rejectFlatCells(sc.mesh, v);
  const std::vector<std::string> faceList = sc.mesh.faceNames();
  const std::set<std::string> faceNames(faceList.begin(), faceList.end());
  std::string faceText;
  for (const auto& f : faceList) faceText += (faceText.empty() ? "" : " ") + f;

  const auto& mat = P.sublist("Material");
  if (mat.get<std::string>("Model") != "Incompressible Neo-Hookean")
    v.fail("Material/Model", "'" + mat.get<std::string>("Model") + "' is not a model (Incompressible Neo-Hookean)");
  sc.c = v.positive(mat, "Material", "c");
  sc.pressurePenalty = v.nonNegative(mat, "Material", "Pressure Penalty");

  sc.bodyForce = v.three<double>(P.sublist("Loads"), "Loads", "Body Force");
  for (double b : sc.bodyForce)
    if (!std::isfinite(b)) v.fail("Loads/Body Force", "must be finite numbers");

  const auto& sups = P.sublist("Supports");
  for (auto it = sups.begin(); it != sups.end(); ++it)
    sc.supports.push_back(SupportSpec::parse(sups.sublist(sups.name(it)), sups.name(it), faceNames, v));
  rejectSupportsHoldingOneComponentTwice(sc.supports, v);

  const auto& caps = P.sublist("Capstans");
  for (auto it = caps.begin(); it != caps.end(); ++it) {
    const std::string name = caps.name(it), path = "Capstans/" + name;
    const auto& c = caps.sublist(name);
    CapstanSpec cs;
    cs.name = name;
    cs.radius = v.positive(c, path, "Radius");
    cs.axisPoint = v.three<double>(c, path, "Axis Point");
    cs.axisDirection = v.three<double>(c, path, "Axis Direction");
    {
      auto& b = cs.axisDirection;
      const double m = std::max({std::fabs(b[0]), std::fabs(b[1]), std::fabs(b[2])});
      if (!(m > 0)) v.fail(path + "/Axis Direction", "must be a non-zero vector, got {0, 0, 0}");
      b = scaledDirection(b);
    }
    cs.velocity = v.three<double>(c, path, "Velocity");
    cs.angularVelocity = v.finite(c, path, "Angular Velocity");
    cs.contactFaces = splitNames(c.get<std::string>("Contact Faces"));
    if (cs.contactFaces.empty()) v.fail(path + "/Contact Faces", "name at least one face");
    for (const auto& f : cs.contactFaces)
      if (!faceNames.count(f)) v.fail(path + "/Contact Faces", "'" + f + "' is not a face of the mesh (" + faceText + ")");
    cs.contact = ContactSettings::parse(c.sublist("Contact"), path + "/Contact", v);
    cs.friction = FrictionSettings::parse(c.sublist("Friction"), path + "/Friction", v);
    solveTinyRegularisationAsCoulomb(cs, path, sc);
    if (cs.friction.on() && !cs.friction.grips())  // runs (its kernel reports stick and slip), carries nothing
      sc.warnings.push_back(sc.file + ": parameter '" + path + "/Friction/Coefficient': 0 with Law = " +
                            nameOf(cs.friction.law, FrictionSettings::laws) +
                            ": the friction kernel runs but carries no traction (Law = None runs none)");
    sc.capstans.push_back(cs);
  }

  const auto& time = P.sublist("Time");
  sc.steps = time.get<int>("Steps");
  if (sc.steps < 1) v.fail("Time/Steps", "must be >= 1, got " + std::to_string(sc.steps));
  sc.stepSize = v.positive(time, "Time", "Step Size");
  // The analysis' own demands first: a steady scene's capstan across the
  // annulus axis is that axis' fault, not the core's it cannot push.
  AnalysisSettings::checkScene(sc, v);
  rejectSingularCores(sc, v);
  if (const std::string rollOff = rollOffDiagnosis(sc); !rollOff.empty())
    sc.warnings.push_back(sc.file + ": parameter 'Supports': " + rollOff);
  if (const std::string fast = fastRollingDiagnosis(sc); !fast.empty())
    sc.warnings.push_back(sc.file + ": parameter 'Time/Step Size': " + fast);
  for (auto& s : sc.supports)
    if (s.isCore() && s.rampTime == 0) s.rampTime = sc.stepSize;
  for (auto& s : sc.supports)
    if (s.isCore() && s.torqueRampTime == 0) s.torqueRampTime = s.rampTime;

  const bool friction = std::any_of(sc.capstans.begin(), sc.capstans.end(),
                                    [](const CapstanSpec& c) { return c.friction.on(); });
  // Quasi-static rolling: a free-turning rigid core (Model::rolling at run time).
  const bool rolling = !sc.analysis.steady() &&
                       std::any_of(sc.supports.begin(), sc.supports.end(), [](const SupportSpec& s) {
                         return s.isCore() && s.rotation == SupportSpec::Rotation::Free;
                       });
  sc.solver = SolverSettings::parse(P.sublist("Solver"), ParameterReader{file}, friction, rolling, sc.analysis.steady());
  for (const auto& c : sc.capstans)
    if (c.friction.on() && sc.solver.linearSolver == SolverSettings::LinearSolver::CG)
      v.fail("Solver/Linear Solver", "CG needs a symmetric matrix; friction on capstan '" + c.name +
                                         "' makes it non-symmetric (use Auto, GMRES or Direct)");

  // Which linear solver the run will use, Auto resolved as Model will (the
  // nodes' unknowns and the cores'): a direct solve builds no preconditioner.
  using Prec = SolverSettings::Preconditioner;
  using Lin = SolverSettings::LinearSolver;
  long dofs = long(3 * nodes);
  for (const auto& s : sc.supports) dofs += s.isCore() ? kCoreUnknowns : 0;
  const bool direct = sc.solver.resolved(dofs, sc.mesh.type == MeshSpec::Type::Annulus, friction,
                                         sc.analysis.steady()).linearSolver == Lin::Direct;
  const std::string precName = nameOf(sc.solver.preconditioner, SolverSettings::preconditioners);
  // Steady rolling makes a free core's rotation unknown its angular velocity,
  // which moves no node: the torque balance's row has no diagonal entry, and
  // MueLu's smoothed aggregation and Jacobi divide by the diagonal (MueLu: "Prolongator
  // damping factor needs to be finite").
  const bool turningSteady = sc.analysis.steady() &&
                             std::any_of(sc.supports.begin(), sc.supports.end(), [](const SupportSpec& s) {
                               return s.isCore() && s.rotation == SupportSpec::Rotation::Free;
                             });
  if (turningSteady && !direct && (sc.solver.preconditioner == Prec::MueLu || sc.solver.preconditioner == Prec::Jacobi))
    v.fail("Solver/Preconditioner", precName +
                                        " cannot precondition steady rolling with a free-turning core: its angular "
                                        "velocity's row (the torque balance) has no diagonal entry (use Auto or LU, "
                                        "ILU, or Linear Solver = Direct)");
  if (direct && sc.solver.preconditioner != Prec::Auto && sc.solver.preconditioner != Prec::None)
    sc.warnings.push_back(sc.file + ": parameter 'Solver/Preconditioner': " + precName + " is not used: " +
                          (sc.solver.linearSolver == Lin::Auto ? "Linear Solver = Auto solves this scene directly"
                                                               : "Linear Solver = Direct factorises the matrix"));

  const auto& out = P.sublist("Output");
  sc.outputDirectory = out.get<std::string>("Directory");
  if (sc.outputDirectory.empty()) v.fail("Output/Directory", "must not be empty");
  sc.writeFields = out.get<bool>("Write Fields");
  sc.checkpointEvery = out.get<int>("Checkpoint Every");
  if (sc.checkpointEvery < 0)
    v.fail("Output/Checkpoint Every", "must be >= 0 (0 = no checkpoints), got " + std::to_string(sc.checkpointEvery));
  for (const auto& c : sc.capstans) warnUnreachable(sc, c);
  return sc;
}

}  // namespace capstan
