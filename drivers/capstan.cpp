// capstan command line (interface.md): run | validate | params | --version.
#include <Teuchos_DefaultComm.hpp>
#include <Teuchos_XMLParameterListHelpers.hpp>
#include <Tpetra_Core.hpp>

#include <algorithm>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "errors.hpp"
#include "heap_tunables.hpp"
#include "log.hpp"
#include "mumps_parameters.hpp"
#include "scene.hpp"
#include "simulation.hpp"

namespace {

const char* kUsage =
    "usage: capstan run SCENE.xml [--output DIR] [--set PATH=VALUE]... [--restart DIR] [--quiet]\n"
    "                             [--log TOPIC]... [--check-tangent]\n"
    "       capstan validate SCENE.xml [--set PATH=VALUE]...\n"
    "       capstan params\n"
    "       capstan --version\n"
    "\n"
    "  --output DIR      write the outputs to DIR (overrides Output/Directory)\n"
    "  --set PATH=VALUE  override one scene parameter, e.g. --set \"Mesh/Cells={28,8,12}\"\n"
    "  --restart DIR     continue from the last checkpoint in DIR, the output directory of an\n"
    "                    earlier run of the scene with Output/Checkpoint Every > 0 (same mesh,\n"
    "                    step size and number of ranks); outputs list every step\n"
    "  --quiet           no progress lines\n"
    "  --log TOPIC       log the method's inner events on stdout and in OUTDIR/log.jsonl;\n"
    "                    topics: newton (Newton histories, constraints, predictors, pressure steps)\n"
    "  --check-tangent   compare the assembled tangent with differences of the residual\n"
    "                    before each Newton solve (a debugging aid; slow)\n"
    "exit status: 0 converged, 1 bad input (nothing written), 2 did not converge\n";

struct Args {
  std::string command, scene, output, restart;
  std::vector<std::string> sets, log;
  bool quiet = false, checkTangent = false;
};

// Returns false (with a message) on a malformed command line.
bool parse(int argc, char** argv, Args& a, std::string& error) {
  if (argc < 2) {
    error = "missing command";
    return false;
  }
  a.command = argv[1];
  for (int i = 2; i < argc; ++i) {
    const std::string s = argv[i];
    auto value = [&](const char* flag) {
      if (i + 1 >= argc || argv[i + 1][0] == '\0') throw std::runtime_error(std::string(flag) + " needs a value");
      return std::string(argv[++i]);
    };
    try {
      if (s == "--output") a.output = value("--output");
      else if (s == "--set") a.sets.push_back(value("--set"));
      else if (s.rfind("--set=", 0) == 0) a.sets.push_back(s.substr(6));
      else if (s.rfind("--output=", 0) == 0 && s.size() > 9) a.output = s.substr(9);
      else if (s == "--output=") throw std::runtime_error("--output needs a value");
      else if (s == "--restart") a.restart = value("--restart");
      else if (s.rfind("--restart=", 0) == 0) a.restart = s.substr(10);
      else if (s == "--quiet") a.quiet = true;
      else if (s == "--check-tangent") a.checkTangent = true;
      else if (s == "--log" || s.rfind("--log=", 0) == 0) {
        const std::string topic = s == "--log" ? value("--log") : s.substr(6);
        const auto& topics = capstan::Log::topics();
        if (std::find(topics.begin(), topics.end(), topic) == topics.end())
          throw std::runtime_error("--log: unknown topic '" + topic + "' (topics: newton)");
        a.log.push_back(topic);
      }
      else if (!s.empty() && s[0] == '-') throw std::runtime_error("unknown option " + s);
      else if (a.scene.empty()) a.scene = s;
      else throw std::runtime_error("unexpected argument " + s);
    } catch (const std::exception& e) {
      error = e.what();
      return false;
    }
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  // Before Kokkos starts: it answers --help with its own options' page.
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h" || (i == 1 && arg == "help")) {
      std::cout << kUsage;
      return 0;
    }
  }
  capstan::reexecWithHeapTunables(argv);  // before MPI starts (src/heap_tunables.hpp)
  Tpetra::ScopeGuard tpetra(&argc, &argv);
  if (capstan::launchedByMpiexec()) capstan::setTcpNoDelay();  // finalize without 40 ms stalls (src/mpi_startup.hpp)
  auto comm = Tpetra::getDefaultComm();
  const bool rank0 = comm->getRank() == 0;
  Args args;
  std::string error;
  if (!parse(argc, argv, args, error)) {
    if (rank0) std::cerr << "capstan: " << error << "\n" << kUsage;
    return 1;
  }
  if (args.command == "--version" || args.command == "version") {
    if (rank0) std::cout << "capstan " << CAPSTAN_VERSION << "\n";
    return 0;
  }
  if (args.command == "params") {
    if (rank0) {
      const auto options = Teuchos::ParameterList::PrintOptions().showDoc(true).showTypes(true).indent(2);
      capstan::validParameters().print(std::cout, options);
      // Stratimikos' list is passed through; the MUMPS part of it is capstan's own.
      std::cout << "\nSolver/Stratimikos/Linear Solver Types/MUMPS (Linear Solver = Direct) and "
                   "Solver/Stratimikos/Preconditioner Types/MUMPS (Preconditioner = LU; Precision: Single by "
                   "default there):\n";
      capstan::validMumpsOptions()->print(std::cout, options);
    }
    return 0;
  }
  if (args.command != "run" && args.command != "validate") {
    if (rank0) std::cerr << "capstan: unknown command '" << args.command << "'\n" << kUsage;
    return 1;
  }
  if (args.scene.empty()) {
    if (rank0) std::cerr << "capstan: " << args.command << " needs a scene file\n" << kUsage;
    return 1;
  }
  if ((!args.restart.empty() || !args.log.empty() || args.checkTangent) && args.command != "run") {
    if (rank0) std::cerr << "capstan: --restart, --log and --check-tangent apply to run only\n" << kUsage;
    return 1;
  }
  try {
    const auto scene = capstan::loadScene(args.scene, args.sets, args.output);
    if (rank0)
      for (const auto& w : scene.warnings) std::cerr << "capstan: WARNING: " << w << "\n";
    if (args.command == "validate") {
      if (rank0) Teuchos::writeParameterListToXmlOStream(capstan::printableScene(scene), std::cout);
      return 0;
    }
    return capstan::runScene(scene, comm, {args.quiet, args.restart, args.log, args.checkTangent});
  } catch (const capstan::InputError& e) {
    if (rank0) std::cerr << "capstan: error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "capstan: internal error on rank " << comm->getRank() << ": " << e.what() << "\n";
    return 3;
  }
}
