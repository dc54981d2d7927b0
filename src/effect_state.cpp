#include "effect_state.hpp"

#include <algorithm>

namespace capstan {

std::vector<double> multipliers(const EffectList& effects, bool accelerated) {
  std::vector<double> out;
  for (const auto& e : effects) {
    if (e->accelerated() != accelerated) continue;
    auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), e->multipliers());
    out.insert(out.end(), h.data(), h.data() + h.size());
  }
  return out;
}

std::vector<double> multiplierMap(const EffectList& effects, bool accelerated) {
  std::vector<double> out;
  for (const auto& e : effects) {
    if (e->accelerated() != accelerated) continue;
    Kokkos::View<double*> next("next multipliers", e->multipliers().extent(0));
    e->multiplierMap(next);
    auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), next);
    out.insert(out.end(), h.data(), h.data() + h.size());
  }
  return out;
}

void setMultipliers(const EffectList& effects, const std::vector<double>& values, bool accelerated,
                    const std::vector<const Effect*>& keep) {
  size_t offset = 0;
  for (const auto& e : effects) {
    if (e->accelerated() != accelerated) continue;
    if (std::find(keep.begin(), keep.end(), e.get()) != keep.end()) {
      offset += e->multipliers().extent(0);
      continue;
    }
    auto view = e->multipliers();
    auto h = Kokkos::create_mirror_view(view);
    for (size_t i = 0; i < h.size(); ++i) h(i) = values[offset + i];
    offset += h.size();
    Kokkos::deep_copy(view, h);
    e->projectMultipliers();
  }
}

EffectState saveState(const EffectList& effects) {
  EffectState s{multipliers(effects, true), multipliers(effects, false), {}};
  for (const auto& e : effects) {
    auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), e->history());
    s.history.insert(s.history.end(), h.data(), h.data() + h.size());
  }
  return s;
}

void restoreState(const EffectList& effects, const EffectState& s) {
  setMultipliers(effects, s.accelerated, true);
  setMultipliers(effects, s.plain, false);
  size_t offset = 0;
  for (const auto& e : effects) {
    auto view = e->history();
    auto h = Kokkos::create_mirror_view(view);
    for (size_t i = 0; i < h.size(); ++i) h(i) = s.history[offset + i];
    offset += h.size();
    Kokkos::deep_copy(view, h);
  }
}

}  // namespace capstan
