#include "scene.hpp"

#include <Teuchos_StrUtils.hpp>
#include <Teuchos_XMLParameterListHelpers.hpp>

#include <fstream>
#include <set>
#include <sstream>

#include "errors.hpp"

namespace capstan {

using Teuchos::Array;
using Teuchos::ParameterList;

namespace {

// Sublists whose children have names chosen by the user: each child is checked
// against this template.
const char* kAnyName = "<any name>";
// Sublists passed through to Trilinos unchanged.
const std::set<std::string> kPassThrough = {"NOX", "Stratimikos"};

Array<double> vec3(double a, double b, double c) { return Teuchos::tuple(a, b, c); }

}  // namespace

ParameterList validParameters() {
  ParameterList p("Scene");
  p.set("Title", std::string(""), "Free text, copied to summary.json");

  auto& mesh = p.sublist("Mesh", false, "The rubber body's mesh");
  mesh.set("Type", std::string("Box"), "Box (structured brick mesh; faces xmin xmax ymin ymax zmin zmax)");
  mesh.set("Min", vec3(0, 0, 0), "Box: lower corner {x, y, z}");
  mesh.set("Max", vec3(1, 1, 1), "Box: upper corner {x, y, z}, each above Min");
  mesh.set("Cells", Array<int>(Teuchos::tuple(4, 4, 4)), "Box: bricks along x, y, z (each >= 1)");

  auto& mat = p.sublist("Material", false, "Rubber (formulation.md §1)");
  mat.set("Model", std::string("Incompressible Neo-Hookean"),
          "Incompressible Neo-Hookean: sigma = -p I + 2c (B - I), Q1P0 bricks");
  mat.set("c", 1.0, "Material constant c > 0 (shear modulus 2c)");
  mat.set("Pressure Penalty", 1e-3,
          "eps1 > 0: pressure penalty of the condensed Newton step. The converged state "
          "(v_e = V_e) does not depend on it; values below Solver/Minimum Solve Penalty "
          "are raised to it in the linear solves (see docs/numerics.md)");

  auto& sup = p.sublist("Supports", false, "Boundary supports, one sublist per support, any name");
  auto& s = sup.sublist(kAnyName, false, "A support");
  s.set("Face", std::string(""), "Name of the mesh face it acts on");
  s.set("Type", std::string("Fixed"), "Fixed | Roller | Foundation | Displacement");
  s.set("Components", std::string("xyz"), "Roller, Foundation, Displacement: components acted on, e.g. \"y\" or \"xz\"");
  s.set("Stiffness", 1.0, "Foundation: k > 0, traction -k (x - X) per reference area");
  s.set("Velocity", vec3(0, 0, 0), "Displacement: u = Velocity * t on the listed components");

  auto& caps = p.sublist("Capstans", false, "Rigid cylinders (formulation.md §2), one sublist each, any name");
  auto& c = caps.sublist(kAnyName, false, "A capstan");
  c.set("Radius", 1.0, "R > 0");
  c.set("Axis Point", vec3(0, 0, 0), "A point a of the axis at t = 0");
  c.set("Axis Direction", vec3(0, 0, 1), "Axis direction beta (non-zero)");
  c.set("Velocity", vec3(0, 0, 0), "Translation of the axis per unit time");
  c.set("Angular Velocity", 0.0, "Spin about the axis, rad per unit time, right-hand rule");
  c.set("Contact Faces", std::string(""), "Candidate contact faces, names separated by spaces or commas");
  auto& contact = c.sublist("Contact", false, "Normal contact");
  contact.set("Method", std::string("Penalty"), "Penalty | Augmented Lagrangian");
  contact.set("Penalty", 1e-3, "eps2 > 0: penetration per unit contact pressure");
  contact.set("Penetration Tolerance", 0.0,
              "Multiplier loop (augmented Lagrangian, or a penalty solved at a larger penalty): "
              "stop when the penetration (or its error against the penalty answer) is below "
              "this; 0 = 1e-4 x the smallest candidate face edge");
  contact.set("Max Augmentations", 50, "Augmented Lagrangian: most multiplier updates per step");
  contact.set("Minimum Solve Penalty", -1.0,
              "Newton solves use eps = max(Penalty, this), and multiplier updates then reach the "
              "answer of Penalty (or exact contact): a well-conditioned solve for any Penalty. "
              "< 0: automatic, 1e-2 h / c with the Nodal rule (h the smallest candidate face edge), "
              "off with Gauss rules; 0: off");
  contact.set("Quadrature", std::string("Auto"),
              "Contact points per face: Auto | Gauss 2x2 | Gauss 3x3 | Nodal (at the face's nodes). "
              "Auto: Gauss 2x2 for Penalty, Nodal for Augmented Lagrangian (exact contact at every "
              "Gauss point of flat faces on a curved capstan over-constrains the body)");
  auto& fr = c.sublist("Friction", false, "Friction between body and capstan (formulation.md §3)");
  fr.set("Law", std::string("None"), "None | Tanh | Arctan | Coulomb");
  fr.set("Coefficient", 0.0, "mu >= 0");
  fr.set("Regularization", 1e-3, "eps3 (Tanh) or eps4 (Arctan) > 0: slip velocity scale");
  fr.set("Tangential Penalty", 0.0,
         "Coulomb: eps_t > 0, tangential slip per unit friction traction while sticking; "
         "0 = the contact's solve penalty");

  auto& time = p.sublist("Time", false, "Quasi-static load steps t_n = n dt");
  time.set("Steps", 1, "Number of steps (>= 1)");
  time.set("Step Size", 1.0, "dt > 0");

  auto& sol = p.sublist("Solver", false, "Nonlinear and linear solvers");
  sol.set("Linear Solver", std::string("Auto"),
          "Auto | GMRES | CG | Direct (Belos GMRES, Belos CG, Amesos2 KLU2). Auto: Direct up to "
          "Direct Solver Max Dofs on one rank, GMRES otherwise");
  sol.set("Direct Solver Max Dofs", 5000, "Auto: largest problem solved directly");
  sol.set("Preconditioner", std::string("Auto"),
          "Auto | ILU | Jacobi | MueLu | None (Ifpack2 RILUK per rank, Jacobi relaxation; MueLu smoothed "
          "aggregation with the rigid-body modes). Auto: MueLu from 1000 dofs, ILU below");
  sol.set("ILU Level", 1, "ILU: level of fill (>= 0)");
  sol.set("Linear Tolerance", 1e-10, "Relative residual of each linear solve (0 < tol < 1)");
  sol.set("Max Linear Iterations", 2000, "Krylov iteration limit per linear solve");
  sol.set("Newton Relative Tolerance", 1e-10, "Converged when |R| <= this x |R| at the step's start");
  sol.set("Newton Absolute Tolerance", 0.0, "Converged when |R| <= this; 0 = 1e-13 x c x (body size)^2");
  sol.set("Max Newton Iterations", 30, "Newton iteration limit per solve");
  sol.set("Predictor", std::string("Tangent"),
          "Tangent (linear response to the step's prescribed increment, from the previous "
          "step) | Previous (the previous step's solution with the new boundary values)");
  sol.set("Line Search", std::string("Backtrack"), "Backtrack | Polynomial | Full Step (NOX line search)");
  sol.set("Volume Tolerance", 1e-10, "Pressure loop ends when max |v_e/V_e - 1| is below this");
  sol.set("Max Pressure Iterations", 100, "Most pressure-anchor updates per step");
  sol.set("Pressure Acceleration Depth", 5,
          "Anderson acceleration depth of the pressure loop (0 = plain pbar <- p(x))");
  sol.set("Minimum Solve Penalty", 1e-2,
          "Smallest eps1 x c used in the Newton solves: below it the condensed pressure "
          "cannot be evaluated in double precision; the pressure loop still makes v_e = V_e exact");
  sol.sublist("NOX", false, "Passed to NOX unchanged, over capstan's defaults");
  sol.sublist("Stratimikos", false, "Passed to Stratimikos unchanged, over capstan's defaults");

  auto& out = p.sublist("Output", false, "Where and what to write");
  out.set("Directory", std::string("out"), "Output directory (created if missing)");
  out.set("Write Fields", true, "Write fields.h5 + fields.xmf");
  return p;
}

namespace {

struct Validator {
  std::string file;

  [[noreturn]] void fail(const std::string& path, const std::string& what) const {
    throw InputError(file + ": " + (path.empty() ? "" : "parameter '" + path + "': ") + what);
  }

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
  if (!typed) throw InputError(file + ": --set: parameter '" + path + "': unknown parameter");
  const auto& t = typed->getAny(false).type();
  try {
    auto number = [&](auto parsed) {
      std::istringstream in(value);
      in >> parsed;
      if (in.fail() || !(in >> std::ws).eof()) throw std::invalid_argument("not a number");
      return parsed;
    };
    if (t == typeid(double)) list->set(name, number(0.0));
    else if (t == typeid(int)) list->set(name, number(0));
    else if (t == typeid(bool)) list->set(name, value == "true" || value == "1");
    else if (t == typeid(std::string)) list->set(name, value);
    else if (t == typeid(Array<double>)) list->set(name, Teuchos::fromStringToArray<double>(value));
    else if (t == typeid(Array<int>)) list->set(name, Teuchos::fromStringToArray<int>(value));
    else throw std::invalid_argument("type not settable");
  } catch (const std::exception& e) {
    throw InputError(file + ": --set: parameter '" + path + "': cannot read '" + value + "' as " +
                     typed->getAny(false).typeName());
  }
}

std::array<bool, 3> components(const std::string& s, const Validator& v, const std::string& path) {
  std::array<bool, 3> on{false, false, false};
  if (s.empty()) v.fail(path, "empty: name at least one of x, y, z");
  for (char ch : s) {
    if (ch == ' ' || ch == ',') continue;
    if (ch < 'x' || ch > 'z') v.fail(path, "'" + s + "': components are letters x, y, z");
    if (on[ch - 'x']) v.fail(path, "'" + s + "': component " + ch + " listed twice");
    on[ch - 'x'] = true;
  }
  return on;
}

template <class T>
std::array<T, 3> three(const ParameterList& l, const std::string& name, const Validator& v,
                       const std::string& path) {
  const auto& a = l.get<Array<T>>(name);
  if (a.size() != 3)
    v.fail(path + "/" + name, "expected 3 values, got " + std::to_string(a.size()));
  return {a[0], a[1], a[2]};
}

double positive(const ParameterList& l, const std::string& name, const Validator& v,
                const std::string& path) {
  const double x = l.get<double>(name);
  if (!(x > 0) || !std::isfinite(x)) v.fail(path + "/" + name, "must be a finite number > 0, got " + Teuchos::toString(x));
  return x;
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

}  // namespace

Scene loadScene(const std::string& file, const std::vector<std::string>& sets,
                const std::string& outputOverride) {
  Validator v{file};
  {
    std::ifstream in(file);
    if (!in) throw InputError(file + ": cannot open the scene file");
    std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (content.find_first_not_of(" \t\r\n") == std::string::npos)
      throw InputError(file + ": the scene file is empty");
    for (unsigned char ch : content)
      if (ch == 0 || (ch < 32 && ch != '\n' && ch != '\r' && ch != '\t'))
        throw InputError(file + ": not a text XML file (binary data)");
  }
  Teuchos::RCP<ParameterList> user;
  try {
    user = Teuchos::getParametersFromXmlFile(file);
  } catch (const std::exception& e) {
    std::string what = e.what();
    if (what.size() > 400) what = what.substr(0, 400) + "...";
    throw InputError(file + ": malformed scene XML: " + what);
  }
  const ParameterList valid = validParameters();
  for (const auto& s : sets) applySet(*user, valid, file, s);
  if (!outputOverride.empty()) user->sublist("Output").set("Directory", outputOverride);
  v.check(*user, valid, "");

  Scene sc;
  sc.file = file;
  sc.resolved = *user;
  const auto& P = sc.resolved;
  sc.title = P.get<std::string>("Title");

  const auto& mesh = P.sublist("Mesh");
  sc.mesh.type = mesh.get<std::string>("Type");
  if (sc.mesh.type != "Box") v.fail("Mesh/Type", "'" + sc.mesh.type + "' is not a mesh type (Box)");
  sc.mesh.min = three<double>(mesh, "Min", v, "Mesh");
  sc.mesh.max = three<double>(mesh, "Max", v, "Mesh");
  sc.mesh.cells = three<int>(mesh, "Cells", v, "Mesh");
  for (int d = 0; d < 3; ++d) {
    if (!(sc.mesh.max[d] > sc.mesh.min[d]))
      v.fail("Mesh/Max", "each component must exceed Mesh/Min (zero or negative size)");
    if (sc.mesh.cells[d] < 1) v.fail("Mesh/Cells", "each count must be >= 1");
  }
  const std::set<std::string> faceNames = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};

  const auto& mat = P.sublist("Material");
  if (mat.get<std::string>("Model") != "Incompressible Neo-Hookean")
    v.fail("Material/Model", "'" + mat.get<std::string>("Model") + "' is not a model (Incompressible Neo-Hookean)");
  sc.c = positive(mat, "c", v, "Material");
  sc.pressurePenalty = positive(mat, "Pressure Penalty", v, "Material");

  const auto& sups = P.sublist("Supports");
  for (auto it = sups.begin(); it != sups.end(); ++it) {
    const std::string name = sups.name(it), path = "Supports/" + name;
    const auto& s = sups.sublist(name);
    SupportSpec spec;
    spec.name = name;
    spec.face = s.get<std::string>("Face");
    spec.type = s.get<std::string>("Type");
    if (!faceNames.count(spec.face)) v.fail(path + "/Face", "'" + spec.face + "' is not a face of the mesh (xmin xmax ymin ymax zmin zmax)");
    if (spec.type == "Fixed") spec.components = {true, true, true};
    else if (spec.type == "Roller" || spec.type == "Foundation" || spec.type == "Displacement")
      spec.components = components(s.get<std::string>("Components"), v, path + "/Components");
    else v.fail(path + "/Type", "'" + spec.type + "' is not a support type (Fixed, Roller, Foundation, Displacement)");
    if (spec.type == "Foundation") spec.stiffness = positive(s, "Stiffness", v, path);
    spec.velocity = three<double>(s, "Velocity", v, path);
    sc.supports.push_back(spec);
  }

  const auto& caps = P.sublist("Capstans");
  for (auto it = caps.begin(); it != caps.end(); ++it) {
    const std::string name = caps.name(it), path = "Capstans/" + name;
    const auto& c = caps.sublist(name);
    CapstanSpec cs;
    cs.name = name;
    cs.radius = positive(c, "Radius", v, path);
    cs.axisPoint = three<double>(c, "Axis Point", v, path);
    cs.axisDirection = three<double>(c, "Axis Direction", v, path);
    const double n2 = cs.axisDirection[0] * cs.axisDirection[0] + cs.axisDirection[1] * cs.axisDirection[1] + cs.axisDirection[2] * cs.axisDirection[2];
    if (!(n2 > 0) || !std::isfinite(n2)) v.fail(path + "/Axis Direction", "must be a non-zero vector");
    cs.velocity = three<double>(c, "Velocity", v, path);
    cs.angularVelocity = c.get<double>("Angular Velocity");
    cs.contactFaces = splitNames(c.get<std::string>("Contact Faces"));
    if (cs.contactFaces.empty()) v.fail(path + "/Contact Faces", "name at least one face");
    for (const auto& f : cs.contactFaces)
      if (!faceNames.count(f)) v.fail(path + "/Contact Faces", "'" + f + "' is not a face of the mesh");
    const auto& ct = c.sublist("Contact");
    cs.method = ct.get<std::string>("Method");
    if (cs.method != "Penalty" && cs.method != "Augmented Lagrangian")
      v.fail(path + "/Contact/Method", "'" + cs.method + "' is not a method (Penalty, Augmented Lagrangian)");
    cs.penalty = positive(ct, "Penalty", v, path + "/Contact");
    cs.penetrationTolerance = ct.get<double>("Penetration Tolerance");
    if (!(cs.penetrationTolerance >= 0)) v.fail(path + "/Contact/Penetration Tolerance", "must be >= 0");
    cs.minimumSolvePenalty = ct.get<double>("Minimum Solve Penalty");
    if (!std::isfinite(cs.minimumSolvePenalty))
      v.fail(path + "/Contact/Minimum Solve Penalty", "must be a finite number");
    const std::string rule = ct.get<std::string>("Quadrature");
    if (rule == "Auto") cs.quadrature = cs.method == "Augmented Lagrangian" ? 2 : 0;
    else if (rule == "Gauss 2x2") cs.quadrature = 0;
    else if (rule == "Gauss 3x3") cs.quadrature = 1;
    else if (rule == "Nodal") cs.quadrature = 2;
    else v.fail(path + "/Contact/Quadrature", "'" + rule + "' is not a rule (Auto, Gauss 2x2, Gauss 3x3, Nodal)");
    if (cs.method == "Augmented Lagrangian" && cs.quadrature != 2)
      v.fail(path + "/Contact/Quadrature",
             "the Augmented Lagrangian needs Nodal (or Auto): zero gap at every Gauss point of flat "
             "faces against a curved capstan is impossible, and the multipliers would never settle");
    cs.maxAugmentations = ct.get<int>("Max Augmentations");
    if (cs.maxAugmentations < 1) v.fail(path + "/Contact/Max Augmentations", "must be >= 1");
    const auto& fr = c.sublist("Friction");
    cs.frictionLaw = fr.get<std::string>("Law");
    if (cs.frictionLaw != "None" && cs.frictionLaw != "Tanh" && cs.frictionLaw != "Arctan" &&
        cs.frictionLaw != "Coulomb")
      v.fail(path + "/Friction/Law", "'" + cs.frictionLaw + "' is not a law (None, Tanh, Arctan, Coulomb)");
    cs.frictionCoefficient = fr.get<double>("Coefficient");
    if (!(cs.frictionCoefficient >= 0) || !std::isfinite(cs.frictionCoefficient))
      v.fail(path + "/Friction/Coefficient", "must be >= 0");
    cs.regularization = fr.get<double>("Regularization");
    if (!(cs.regularization > 0) || !std::isfinite(cs.regularization))
      v.fail(path + "/Friction/Regularization", "must be > 0");
    cs.tangentialPenalty = fr.get<double>("Tangential Penalty");
    if (!(cs.tangentialPenalty >= 0) || !std::isfinite(cs.tangentialPenalty))
      v.fail(path + "/Friction/Tangential Penalty", "must be >= 0");
    sc.capstans.push_back(cs);
  }

  const auto& time = P.sublist("Time");
  sc.steps = time.get<int>("Steps");
  if (sc.steps < 1) v.fail("Time/Steps", "must be >= 1, got " + std::to_string(sc.steps));
  sc.stepSize = positive(time, "Step Size", v, "Time");

  sc.solver = P.sublist("Solver");
  const auto& sol = sc.solver;
  auto oneOf = [&](const std::string& name, std::set<std::string> allowed) {
    const auto& val = sol.get<std::string>(name);
    if (!allowed.count(val)) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      v.fail("Solver/" + name, "'" + val + "' is not one of " + list);
    }
  };
  oneOf("Linear Solver", {"Auto", "GMRES", "CG", "Direct"});
  for (const auto& c : sc.capstans)
    if (c.frictionLaw != "None" && sol.get<std::string>("Linear Solver") == "CG")
      v.fail("Solver/Linear Solver", "CG needs a symmetric matrix; friction on capstan '" + c.name +
                                         "' makes it non-symmetric (use Auto, GMRES or Direct)");
  oneOf("Preconditioner", {"Auto", "ILU", "Jacobi", "MueLu", "None"});
  oneOf("Line Search", {"Backtrack", "Polynomial", "Full Step"});
  oneOf("Predictor", {"Tangent", "Previous"});
  for (const char* n : {"Linear Tolerance", "Newton Relative Tolerance", "Volume Tolerance"}) {
    const double x = sol.get<double>(n);
    if (!(x > 0 && x < 1)) v.fail(std::string("Solver/") + n, "must be in (0, 1)");
  }
  if (!(sol.get<double>("Newton Absolute Tolerance") >= 0)) v.fail("Solver/Newton Absolute Tolerance", "must be >= 0");
  positive(sol, "Minimum Solve Penalty", v, "Solver");
  for (const char* n : {"Max Linear Iterations", "Max Newton Iterations", "Max Pressure Iterations"})
    if (sol.get<int>(n) < 1) v.fail(std::string("Solver/") + n, "must be >= 1");
  if (sol.get<int>("ILU Level") < 0) v.fail("Solver/ILU Level", "must be >= 0");
  if (sol.get<int>("Pressure Acceleration Depth") < 0) v.fail("Solver/Pressure Acceleration Depth", "must be >= 0");

  const auto& out = P.sublist("Output");
  sc.outputDirectory = out.get<std::string>("Directory");
  if (sc.outputDirectory.empty()) v.fail("Output/Directory", "must not be empty");
  sc.writeFields = out.get<bool>("Write Fields");
  return sc;
}

}  // namespace capstan
