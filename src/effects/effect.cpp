#include "effect.hpp"

#include <Kokkos_Timer.hpp>

namespace capstan {

void Effect::evaluate(const NodalVectors& x, const NodalVectors& u, const TangentSink* sink) {
  Kokkos::Timer timer;
  launch(x, u, sink != nullptr, sink ? *sink : TangentSink{});
  Kokkos::fence();
  seconds_ += timer.seconds();
  ++launches_;
}

}  // namespace capstan
