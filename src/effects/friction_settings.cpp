#include "friction_settings.hpp"

namespace capstan {

const std::vector<std::pair<const char*, FrictionSettings::Law>> FrictionSettings::laws = {
    {"None", Law::None}, {"Tanh", Law::Tanh}, {"Arctan", Law::Arctan}, {"Coulomb", Law::Coulomb}};

void FrictionSettings::declare(Teuchos::ParameterList& fr) {
  fr.set("Law", std::string("None"), "None | Tanh | Arctan | Coulomb");
  fr.set("Coefficient", 0.0, "mu >= 0");
  fr.set("Regularization", 1e-3,
         "eps3 (Tanh) or eps4 (Arctan) > 0: slip velocity scale; below 3e-7 of the capstan's surface "
         "speed the law is solved as its limit, Coulomb, with a warning (docs/friction.md)");
  fr.set("Tangential Penalty", 0.0,
         "Coulomb: eps_t > 0, tangential slip per unit friction traction while sticking; "
         "0 = the contact's solve penalty");
  fr.set("Smoothing", 0.0,
         "Coulomb: width delta >= 0 of a smoothed stick/slip corner, t = t* / m(|t*| / (mu t_n)) with "
         "m(s) = (1 + s + sqrt((s-1)^2 + delta^2)) / 2: |t| <= mu t_n still, sticking traction "
         "softened by about delta^2/4. Removes the corner at which Newton stalls when points keep "
         "switching between stick and slip (rolling); 0 = the exact return mapping");
}

FrictionSettings FrictionSettings::parse(const Teuchos::ParameterList& fr, const std::string& path,
                                         const ParameterReader& r) {
  FrictionSettings s;
  s.law = r.choice(fr, path, "Law", laws);
  s.coefficient = r.nonNegative(fr, path, "Coefficient");
  s.regularization = r.positive(fr, path, "Regularization");
  s.smoothing = r.nonNegative(fr, path, "Smoothing");
  s.tangentialPenalty = r.nonNegative(fr, path, "Tangential Penalty");
  return s;
}

}  // namespace capstan
