// Two 0.1 x 0.04 rectangles overlapping over half their length, not fused (OpenCASCADE).
SetFactory("OpenCASCADE");
Rectangle(1) = {0, 0, 0, 0.1, 0.04};
Rectangle(2) = {0.05, 0, 0, 0.1, 0.04};
