// The quarter of the 2D ring 1 <= r <= 2 with x, y >= 0 in the z = 0 plane (OpenCASCADE): no
// central symmetry. Surface "wall".
SetFactory("OpenCASCADE");
Disk(1) = {0, 0, 0, 2};
Disk(2) = {0, 0, 0, 1};
BooleanDifference(3) = {Surface{1}; Delete;}{Surface{2}; Delete;};
Rectangle(4) = {0, 0, 0, 2, 2};
BooleanIntersection(5) = {Surface{3}; Delete;}{Surface{4}; Delete;};
Physical Surface("wall") = {5};
