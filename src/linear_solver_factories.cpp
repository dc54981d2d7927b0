#include "linear_solver_factories.hpp"

#include <Teuchos_AbstractFactoryStd.hpp>
#include <Thyra_BelosLinearOpWithSolveFactory.hpp>
#include <dlfcn.h>
#include <unistd.h>

#include <climits>
#include <set>
#include <string>

#include "mumps_solve_factory.hpp"

namespace capstan {

namespace {

using Teuchos::ParameterList;
using Teuchos::RCP;
using Teuchos::rcp;

// Only `kind`'s sublist `name` (or nothing) inside `list`'s sublist `kind`.
bool onlySublist(const ParameterList& list, const std::string& kind, const std::string& name) {
  if (!list.isParameter(kind)) return true;
  if (!list.isSublist(kind)) return false;
  for (const auto& entry : list.sublist(kind))
    if (entry.first != name) return false;
  return true;
}

std::string stringOr(const ParameterList& list, const std::string& name) {
  return list.isType<std::string>(name) ? list.get<std::string>(name) : std::string();
}

RCP<ParameterList> copyOf(const ParameterList& list, const std::string& kind, const std::string& name) {
  if (!list.isSublist(kind) || !list.sublist(kind).isSublist(name)) return rcp(new ParameterList(name));
  return rcp(new ParameterList(list.sublist(kind).sublist(name)));
}

// The plugin beside the running program, else where the build put it.
void* openPlugin() {
  const char* file = "libcapstan_krylov.so";
  char self[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
  std::string tried;
  if (n > 0) {
    std::string path(self, size_t(n));
    path = path.substr(0, path.rfind('/') + 1) + file;
    if (void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL)) return handle;
    tried = path + " (" + dlerror() + ")";
  }
#ifdef CAPSTAN_KRYLOV_PLUGIN
  if (void* handle = dlopen(CAPSTAN_KRYLOV_PLUGIN, RTLD_NOW | RTLD_LOCAL)) return handle;
  tried += std::string(tried.empty() ? "" : ", ") + CAPSTAN_KRYLOV_PLUGIN + " (" + dlerror() + ")";
#endif
  throw PluginError("cannot load capstan's Krylov solver plugin, needed for this scene's linear solver: tried " +
                    tried);
}

BuildFromStratimikos pluginEntry() {
  static BuildFromStratimikos entry = nullptr;  // loaded once, kept for the process
  if (entry) return entry;
  void* handle = openPlugin();
  entry = reinterpret_cast<BuildFromStratimikos>(dlsym(handle, kBuildFromStratimikosName));
  if (!entry) throw PluginError(std::string("capstan's Krylov solver plugin has no ") + kBuildFromStratimikosName);
  return entry;
}

}  // namespace

bool builtWithoutStratimikos(const ParameterList& p) {
  static const std::set<std::string> known = {"Linear Solver Type", "Preconditioner Type", "Linear Solver Types",
                                              "Preconditioner Types"};
  for (const auto& entry : p)
    if (!known.count(entry.first)) return false;
  const std::string lows = stringOr(p, "Linear Solver Type"), prec = stringOr(p, "Preconditioner Type");
  if (lows != "MUMPS" && lows != "Belos") return false;
  if (prec != "None" && prec != "MUMPS") return false;
  if (lows == "MUMPS" && prec != "None") return false;  // the builder would build it unused
  return onlySublist(p, "Linear Solver Types", lows) &&
         onlySublist(p, "Preconditioner Types", prec == "None" ? std::string() : prec);
}

LinearSolverFactories linearSolverFactories(const ParameterList& p) {
  LinearSolverFactories f;
  if (!builtWithoutStratimikos(p)) {
    StratimikosRequest request;
    request.list = &p;
    request.mumpsSolve =
        Teuchos::abstractFactoryStd<Thyra::LinearOpWithSolveFactoryBase<double>, MumpsSolveFactory>();
    request.mumpsPreconditioner =
        Teuchos::abstractFactoryStd<Thyra::PreconditionerFactoryBase<double>, MumpsPreconditionerFactory>();
    pluginEntry()(request);
    return request.built;
  }
  // As Stratimikos' builder does it: the preconditioner factory first, then
  // the solver's own parameters (which may override the preconditioner's).
  const std::string lows = p.get<std::string>("Linear Solver Type");
  if (p.get<std::string>("Preconditioner Type") == "MUMPS") {
    f.prec = rcp(new MumpsPreconditionerFactory());
    f.prec->setParameterList(copyOf(p, "Preconditioner Types", "MUMPS"));
  }
  if (lows == "MUMPS")
    f.lows = rcp(new MumpsSolveFactory());
  else
    f.lows = rcp(new Thyra::BelosLinearOpWithSolveFactory<double>());
  if (!f.prec.is_null() && f.lows->acceptsPreconditionerFactory()) {
    auto own = rcp(new MumpsPreconditionerFactory());  // the builder gives the solver its own
    own->setParameterList(copyOf(p, "Preconditioner Types", "MUMPS"));
    f.lows->setPreconditionerFactory(own, "MUMPS");
  }
  f.lows->setParameterList(copyOf(p, "Linear Solver Types", lows));
  return f;
}

}  // namespace capstan
