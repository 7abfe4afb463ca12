// Two unit cubes overlapping over half their length, not fused (OpenCASCADE).
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 1};
Box(2) = {0.5, 0, 0, 1, 1, 1};
