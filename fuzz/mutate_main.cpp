// A standalone driver for fuzz/scene_fuzz.cpp where libFuzzer is not at hand
// (the normal gcc build, ctest -L fuzz): mutates the seed scenes (every .xml
// under the given files or directories) at random, in process, and feeds each
// mutant to LLVMFuzzerTestOneInput.
//
//   scene_fuzz_mutate [--seconds T] [--iterations N] [--seed S] [--crashes DIR] SEEDS...
//
// Mutations, 1 to 4 per input, XML-aware where it pays: bit flips, random
// bytes, truncation, deleted or duplicated ranges, splices from another seed,
// deleted elements and attributes, attribute values replaced by edge cases
// (empty, 0, -1, 1e308, nan, {}, lists of the wrong length, huge ints, unknown
// face names), types swapped, names replaced, XML fragments inserted. A finding
// (an exception other than InputError, a crash, an abort, an input that takes
// longer than --hang seconds) writes the input to DIR/crash-<n>.xml first and
// ends the run with a non-zero status.
#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);
extern long capstanFuzzValidScenes;

namespace {

namespace fs = std::filesystem;

// The input being tested, for the signal handler.
const std::string* gCurrent = nullptr;
char gCrashPath[4096] = "crash-input.xml";

void saveAndDie(int sig) {
  // Async-signal-safe: open/write/close only.
  if (gCurrent) {
    const int fd = ::open(gCrashPath, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      const char* p = gCurrent->data();
      size_t left = gCurrent->size();
      while (left > 0) {
        const ssize_t n = ::write(fd, p, left);
        if (n <= 0) break;
        p += n, left -= size_t(n);
      }
      ::close(fd);
    }
    const char msg[] = "\nscene_fuzz_mutate: finding; the input is in ";
    (void)!::write(2, msg, sizeof msg - 1);
    (void)!::write(2, gCrashPath, std::strlen(gCrashPath));
    (void)!::write(2, "\n", 1);
  }
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

const std::vector<std::string> kValues = {
    "", " ", "0", "-0", "-1", "1", "2", "1e308", "-1e308", "1e999", "1e-320", "nan", "inf", "-inf",
    "0x10", "abc", "1.5", " 7 ", "2147483647", "-2147483648", "2147483648", "99999999999999999999",
    "{}", "{", "}", "{,}", "{1}", "{1,2}", "{0,0,0}", "{1,2,3}", "{1,2,3,4}", "{-1,-1,-1}",
    "{1e308,1e308,1e308}", "{nan,0,0}", "{2147483647,2147483647,2147483647}", "{100000,100000,100000}",
    "{1,0,1}", "{0.5,0.5,0.5}", "true", "false", "maybe", "xmin", "ymax", "top", "ymax top",
    "xmax,ymin", "x", "xyz", "xx", "w", "Fixed", "Roller", "Foundation", "Displacement", "Rigid Core",
    "Penalty", "Augmented Lagrangian", "Coulomb", "Tanh", "None", "Direct", "CG", "MueLu", "Box",
    "Annulus", "&amp;", "&lt;", "&#0;", "&#65;", "\xc3\xa9", "\xff\xfe", "a/b", "..", "/"};
const std::vector<std::string> kTypes = {"double", "int", "string", "bool", "Array(double)",
                                         "Array(int)", "Array(string)", "float", "complex", "",
                                         "long long", "char", "TwoDArray(double)"};
const std::vector<std::string> kNames = {
    "Mesh", "Material", "Supports", "Capstans", "Time", "Solver", "Output", "Type", "Min", "Max",
    "Cells", "c", "Pressure Penalty", "Face", "Components", "Stiffness", "Velocity", "Radius",
    "Axis Point", "Axis Direction", "Angular Velocity", "Contact Faces", "Contact", "Method",
    "Penalty", "Friction", "Law", "Coefficient", "Regularization", "Steps", "Step Size",
    "Directory", "Write Fields", "Checkpoint Every", "NOX", "Stratimikos", "Linear Solver",
    "Preconditioner", "Line Search", "Quadrature", "<any name>", "", "x/y", "Scene"};
const std::vector<std::string> kFragments = {
    "<ParameterList name=\"x\">", "</ParameterList>", "<ParameterList>", "<Parameter/>",
    "<Parameter name=\"c\" type=\"double\" value=\"1\"/>", "<!--", "-->", "<![CDATA[", "]]>",
    "<?xml version=\"1.0\"?>", "<!DOCTYPE x>", "&amp;", "&bogus;", "&#0;", "\"", "'", "<", ">",
    "/>", "=", "<Foo/>", "<ParameterList name=\"Mesh\"></ParameterList>",
    "<ParameterList name=\"NOX\"><Parameter name=\"Nonlinear Solver\" type=\"string\" value=\"Bogus\"/></ParameterList>",
    "<ParameterList name=\"Stratimikos\"><Parameter name=\"Linear Solver Type\" type=\"string\" value=\"Belos\"/></ParameterList>"};

class Mutator {
 public:
  Mutator(std::vector<std::string> seeds, uint64_t seed) : seeds_(std::move(seeds)), rng_(seed) {}

  std::string next() {
    std::string s = seeds_[pick(seeds_.size())];
    const int n = 1 + int(pick(4));
    for (int i = 0; i < n; ++i) mutate(s);
    return s;
  }

 private:
  size_t pick(size_t n) { return n ? std::uniform_int_distribution<size_t>(0, n - 1)(rng_) : 0; }
  template <class V>
  const auto& any(const V& v) {
    return v[pick(v.size())];
  }

  // [begin, end) of the quoted text of a random attribute `attr="..."`, or false.
  bool attribute(const std::string& s, const std::string& attr, size_t& begin, size_t& end) {
    std::vector<size_t> at;
    const std::string key = attr + "=\"";
    for (size_t p = s.find(key); p != std::string::npos; p = s.find(key, p + 1)) at.push_back(p);
    if (at.empty()) return false;
    begin = any(at) + key.size();
    end = s.find('"', begin);
    return end != std::string::npos;
  }

  void mutate(std::string& s) {
    size_t b = 0, e = 0;
    switch (pick(14)) {
      case 0:  // bit flip
        if (!s.empty()) s[pick(s.size())] ^= char(1u << pick(8));
        break;
      case 1:  // random byte
        if (!s.empty()) s[pick(s.size())] = char(pick(256));
        break;
      case 2:  // truncate
        s.resize(pick(s.size() + 1));
        break;
      case 3:  // delete a range
        if (!s.empty()) {
          b = pick(s.size());
          s.erase(b, 1 + pick(std::min<size_t>(64, s.size() - b)));
        }
        break;
      case 4:  // duplicate a range
        if (!s.empty()) {
          b = pick(s.size());
          const std::string r = s.substr(b, 1 + pick(64));
          s.insert(pick(s.size() + 1), r);
        }
        break;
      case 5: {  // splice from another seed
        const std::string& o = any(seeds_);
        b = pick(o.size() + 1);
        s.insert(pick(s.size() + 1), o.substr(b, pick(256)));
        break;
      }
      case 6:  // delete an element <...>
        b = s.find('<', pick(s.size() + 1));
        if (b != std::string::npos && (e = s.find('>', b)) != std::string::npos) s.erase(b, e - b + 1);
        break;
      case 7: {  // delete an attribute
        static const char* attrs[] = {"name", "type", "value"};
        if (attribute(s, attrs[pick(3)], b, e)) {
          const size_t start = s.rfind(' ', b);
          if (start != std::string::npos && start < b) s.erase(start, e + 1 - start);
        }
        break;
      }
      case 8:
      case 9:  // an edge-case value
        if (attribute(s, "value", b, e)) s.replace(b, e - b, any(kValues));
        break;
      case 10:  // another type
        if (attribute(s, "type", b, e)) s.replace(b, e - b, any(kTypes));
        break;
      case 11:  // another name
        if (attribute(s, "name", b, e)) s.replace(b, e - b, any(kNames));
        break;
      case 12:  // an XML fragment
        s.insert(pick(s.size() + 1), any(kFragments));
        break;
      case 13:  // a random number in a value
        if (attribute(s, "value", b, e)) {
          std::uniform_real_distribution<double> u(-10, 10);
          s.replace(b, e - b, std::to_string(u(rng_) * std::pow(10.0, double(pick(9)) - 4)));
        }
        break;
    }
  }

  std::vector<std::string> seeds_;
  std::mt19937_64 rng_;
};

std::vector<std::string> loadSeeds(const std::vector<std::string>& paths) {
  std::vector<std::string> files, seeds;
  for (const auto& p : paths) {
    if (fs::is_directory(p)) {
      for (const auto& entry : fs::recursive_directory_iterator(p))
        if (entry.is_regular_file() && entry.path().extension() == ".xml") files.push_back(entry.path().string());
    } else {
      files.push_back(p);
    }
  }
  std::sort(files.begin(), files.end());  // the same sequence for the same --seed
  for (const auto& f : files) {
    std::ifstream in(f, std::ios::binary);
    seeds.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  return seeds;
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 20, hang = 10;
  long long iterations = -1;
  uint64_t seed = 1;
  std::string crashes = ".";
  std::vector<std::string> paths;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "scene_fuzz_mutate: " << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--seconds") seconds = std::stod(value());
    else if (a == "--iterations") iterations = std::stoll(value());
    else if (a == "--seed") seed = std::stoull(value());
    else if (a == "--hang") hang = std::stod(value());
    else if (a == "--crashes") crashes = value();
    else paths.push_back(a);
  }
  const auto seeds = loadSeeds(paths);
  if (seeds.empty()) {
    std::cerr << "usage: scene_fuzz_mutate [--seconds T] [--iterations N] [--seed S] [--hang T] "
                 "[--crashes DIR] SEED_FILES_OR_DIRS...\n";
    return 2;
  }
  std::snprintf(gCrashPath, sizeof gCrashPath, "%s/crash-seed%llu.xml", crashes.c_str(),
                (unsigned long long)seed);
  for (int sig : {SIGABRT, SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGALRM}) ::signal(sig, saveAndDie);

  // Every seed as it is first: they must all be valid scenes or input errors too.
  Mutator mutator(seeds, seed);
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  long long n = 0;
  double slowest = 0;
  size_t longest = 0;
  for (;; ++n) {
    const double elapsed = std::chrono::duration<double>(Clock::now() - t0).count();
    if ((iterations >= 0 && n >= iterations) || (iterations < 0 && elapsed >= seconds)) break;
    const std::string input = n < (long long)seeds.size() ? seeds[size_t(n)] : mutator.next();
    gCurrent = &input;
    ::alarm(unsigned(std::max(1.0, hang)));  // a hang is a finding: SIGALRM saves the input
    const auto t = Clock::now();
    LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(input.data()), input.size());
    const double dt = std::chrono::duration<double>(Clock::now() - t).count();
    ::alarm(0);
    gCurrent = nullptr;
    if (dt > slowest) slowest = dt, longest = input.size();
  }
  const double total = std::chrono::duration<double>(Clock::now() - t0).count();
  std::printf("scene_fuzz_mutate: %lld inputs from %zu seeds in %.1f s (seed %llu), %ld valid scenes, "
              "the rest input errors; no finding; slowest input %.3f s (%zu bytes)\n",
              n, seeds.size(), total, (unsigned long long)seed, capstanFuzzValidScenes, slowest, longest);
  return 0;
}
