// An L-bracket: a base plate with a bolt hole and an upright arm, a fillet in the inner corner.
// Units: m. Base x 0..0.08, y 0..0.04, z 0..0.01; arm x 0..0.01, z 0..0.06; fillet radius 5 mm;
// bolt hole radius 5 mm through the base at (0.055, 0.02).
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 0.08, 0.04, 0.01};
Box(2) = {0, 0, 0, 0.01, 0.04, 0.06};
BooleanUnion(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
corner() = Curve In BoundingBox{0.01 - 1e-6, -1e-6, 0.01 - 1e-6, 0.01 + 1e-6, 0.04 + 1e-6, 0.01 + 1e-6};
f() = Fillet{3}{corner()}{0.005};
Cylinder(10) = {0.055, 0.02, -0.001, 0, 0, 0.012, 0.005};
BooleanDifference(11) = { Volume{f(0)}; Delete; }{ Volume{10}; Delete; };
Physical Volume("bracket") = {11};
bore() = Surface In BoundingBox{0.05 - 1e-6, 0.015 - 1e-6, -1e-6, 0.06 + 1e-6, 0.025 + 1e-6, 0.01 + 1e-6};
Physical Surface("bore") = {bore()};
load() = Surface In BoundingBox{0.01 - 1e-6, -1e-6, 0.015 - 1e-6, 0.01 + 1e-6, 0.04 + 1e-6, 0.06 + 1e-6};
Physical Surface("arm_face") = {load()};
