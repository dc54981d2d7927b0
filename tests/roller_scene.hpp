// The test roller shared by tests/test_rigid_core.cpp and
// tests/test_steady_rolling.cpp: a 2-cell annulus on a rigid core, free to
// move and turn, pressed by a spinning capstan with Tanh friction. Each test
// adjusts it with --set style overrides (parseScene's `sets`).
#pragma once

namespace capstan::test {

inline const char* const kRollerScene = R"xml(<ParameterList name="Scene">
  <ParameterList name="Mesh">
    <Parameter name="Type" type="string" value="Annulus"/>
    <Parameter name="Inner Radius" type="double" value="1"/>
    <Parameter name="Outer Radius" type="double" value="2"/>
    <Parameter name="Length" type="double" value="0.6"/>
    <Parameter name="Cells" type="Array(int)" value="{2, 12, 2}"/>
  </ParameterList>
  <ParameterList name="Material"><Parameter name="c" type="double" value="1.3"/></ParameterList>
  <ParameterList name="Supports">
    <ParameterList name="core">
      <Parameter name="Face" type="string" value="inner"/>
      <Parameter name="Type" type="string" value="Rigid Core"/>
      <Parameter name="Axis Point" type="Array(double)" value="{0.1, -0.2, 0}"/>
      <Parameter name="Axis Direction" type="Array(double)" value="{0.1, 0.2, 1}"/>
      <Parameter name="Free Translation" type="string" value="xy"/>
      <Parameter name="Force" type="Array(double)" value="{0.3, -0.5, 0}"/>
      <Parameter name="Rotation" type="string" value="Free"/>
      <Parameter name="Torque" type="double" value="0.2"/>
    </ParameterList>
  </ParameterList>
  <ParameterList name="Capstans">
    <ParameterList name="capstan">
      <Parameter name="Radius" type="double" value="1"/>
      <Parameter name="Axis Point" type="Array(double)" value="{0, -2.9, 0}"/>
      <Parameter name="Angular Velocity" type="double" value="0.5"/>
      <Parameter name="Contact Faces" type="string" value="outer"/>
      <ParameterList name="Contact"><Parameter name="Penalty" type="double" value="0.05"/></ParameterList>
      <ParameterList name="Friction">
        <Parameter name="Law" type="string" value="Tanh"/>
        <Parameter name="Coefficient" type="double" value="0.6"/>
        <Parameter name="Regularization" type="double" value="0.5"/>
      </ParameterList>
    </ParameterList>
  </ParameterList>
  <ParameterList name="Output"><Parameter name="Directory" type="string" value="unused"/></ParameterList>
</ParameterList>)xml";

}  // namespace capstan::test
