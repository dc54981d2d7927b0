// The effects' augmentation multipliers and history as flat host vectors: what
// the augmentation loop mixes, and what a failed increment puts back.
#pragma once

#include <memory>
#include <vector>

#include "effects/effect.hpp"

namespace capstan {

using EffectList = std::vector<std::unique_ptr<Effect>>;

// This rank's multipliers of the effects that are (or are not) Anderson-
// accelerated, effect after effect.
std::vector<double> multipliers(const EffectList& effects, bool accelerated);
// Their fixed-point map G at the last evaluation, in the same layout.
std::vector<double> multiplierMap(const EffectList& effects, bool accelerated);
// Sets them (and projects each effect's onto its admissible set); `keep`:
// effects whose multipliers stay as they are.
void setMultipliers(const EffectList& effects, const std::vector<double>& values, bool accelerated,
                    const std::vector<const Effect*>& keep = {});

// What a failed increment must undo: the multipliers and the effects' history
// (committed by the converged sub-steps of a step that fails later).
struct EffectState {
  std::vector<double> accelerated, plain, history;
};
EffectState saveState(const EffectList& effects);
void restoreState(const EffectList& effects, const EffectState& state);

}  // namespace capstan
