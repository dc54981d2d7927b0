// Fuzz target for the scene parser: arbitrary bytes as a scene file, through
// parseScene (the parse + validation `capstan run` and `capstan validate` use).
// The contract: a valid Scene or a capstan::InputError, nothing else. Any other
// exception is reported and aborts (a finding); crashes, hangs and sanitizer
// reports are findings by themselves.
//
// Built two ways (fuzz/README.md):
//   * with libFuzzer: scripts/fuzz.sh (clang, -fsanitize=fuzzer,address), and
//   * with fuzz/mutate_main.cpp, a standalone seed mutator, in the normal build
//     (scene_fuzz_mutate; ctest -L fuzz runs it for 20 s).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <typeinfo>

#include "errors.hpp"
#include "scene.hpp"

// Inputs that were valid scenes (the standalone driver reports the share).
long capstanFuzzValidScenes = 0;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string content(reinterpret_cast<const char*>(data), size);
  try {
    const capstan::Scene scene = capstan::parseScene(content, "fuzz.xml", {}, "");
    ++capstanFuzzValidScenes;
    // A valid scene must be internally consistent with what validation promises.
    if (scene.steps < 1 || !(scene.stepSize > 0) || scene.outputDirectory.empty()) {
      std::fprintf(stderr, "scene_fuzz: a scene passed validation with steps %d, step size %g\n",
                   scene.steps, scene.stepSize);
      std::abort();
    }
  } catch (const capstan::InputError&) {
    // The expected answer to bad input.
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scene_fuzz: %s escaped parseScene: %s\n", typeid(e).name(), e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "scene_fuzz: a non-std exception escaped parseScene\n");
    std::abort();
  }
  return 0;
}
