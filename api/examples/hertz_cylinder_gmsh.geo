// hertz_cylinder.json in Gmsh form: a slice x in [0, 6] of a cylinder of radius 10 (centre (0, 10)) pressed on a
// block [0, 20] x [-20, 0], symmetry at x = 0. The cylinder is meshed in triangles, the block in quadrangles
// where the recombination finds them and triangles elsewhere (a mixed mesh); both 0.02 near the contact.
// Generated into hertz_cylinder_gmsh.msh by scripts/make_gmsh_examples.sh.
SetFactory("Built-in");
Geometry.AutoCoherence = 0;  // the bodies touch at the origin but must keep their own nodes

R = 10;
h_fine = 0.02; h_coarse = 2;

// Block.
Point(1) = {0, -20, 0, h_coarse}; Point(2) = {20, -20, 0, h_coarse}; Point(3) = {20, 0, 0, h_coarse};
Point(4) = {0, 0, 0, h_fine};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};

// Cylinder slice: the arc from the origin to (6, 2), then straight sides.
Point(11) = {0, 0, 0, h_fine}; Point(12) = {6, 2, 0, h_coarse}; Point(13) = {6, 12, 0, h_coarse};
Point(14) = {0, 12, 0, h_coarse}; Point(15) = {0, R, 0};  // the centre
Circle(11) = {11, 15, 12}; Line(12) = {12, 13}; Line(13) = {13, 14}; Line(14) = {14, 11};
Curve Loop(2) = {11, 12, 13, 14}; Plane Surface(2) = {2};

// Sizes: h_fine within 1.2 of the contact point, growing to h_coarse at distance 12.
Field[1] = Distance; Field[1].PointsList = {4, 11};
Field[2] = Threshold; Field[2].InField = 1;
Field[2].SizeMin = h_fine; Field[2].SizeMax = h_coarse; Field[2].DistMin = 1.2; Field[2].DistMax = 12;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0; Mesh.MeshSizeFromPoints = 0; Mesh.MeshSizeFromCurvature = 0;
Recombine Surface{1};
Mesh.RecombinationAlgorithm = 0;  // simple: leaves some triangles, so the block is a mixed mesh

Physical Surface("lower") = {1};
Physical Surface("upper") = {2};
Physical Curve("lower_bottom") = {1};
Physical Curve("lower_top") = {3};
Physical Curve("symmetry") = {4, 14};
Physical Curve("upper_bottom") = {11};
Physical Curve("upper_top") = {13};
