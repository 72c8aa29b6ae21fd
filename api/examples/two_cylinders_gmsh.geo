// Two half-cylinders of different radii and materials (issue 20): a steel cylinder of radius 10 (centre (0, 10),
// the lower half-disc, flat face y = 10 on top) pressed on an aluminium cylinder of radius 25 (centre (0, -25),
// the upper half-disc, flat face y = -25 at the bottom); they touch at the origin. Triangles, a coarse start
// (~1.4k unknowns in all) for h-adaptivity: 0.25 near the contact point growing to 2 away from it.
// Generated into two_cylinders_gmsh.msh by scripts/make_gmsh_examples.sh; used by two_cylinders_gmsh.json.
SetFactory("Built-in");
Geometry.AutoCoherence = 0;  // the bodies touch at the origin but must keep their own nodes

R1 = 10; R2 = 25;
h_fine = 0.25; h_coarse = 2;

// Aluminium (lower): arc from (R2, -R2) over the top (0, 0) to (-R2, -R2), then the flat face.
Point(1) = {R2, -R2, 0, h_coarse}; Point(2) = {0, 0, 0, h_fine}; Point(3) = {-R2, -R2, 0, h_coarse};
Point(4) = {0, -R2, 0, h_coarse};  // the centre
Circle(1) = {1, 4, 2}; Circle(2) = {2, 4, 3}; Line(3) = {3, 1};
Curve Loop(1) = {1, 2, 3}; Plane Surface(1) = {1};

// Steel (upper): arc from (-R1, R1) down through (0, 0) to (R1, R1), then the flat face.
Point(11) = {-R1, R1, 0, h_coarse}; Point(12) = {0, 0, 0, h_fine}; Point(13) = {R1, R1, 0, h_coarse};
Point(14) = {0, R1, 0, h_coarse};  // the centre
Circle(11) = {11, 14, 12}; Circle(12) = {12, 14, 13}; Line(13) = {13, 11};
Curve Loop(2) = {11, 12, 13}; Plane Surface(2) = {2};

// Sizes: h_fine within 1 of the contact point, growing to h_coarse at distance 10.
Field[1] = Distance; Field[1].PointsList = {2, 12};
Field[2] = Threshold; Field[2].InField = 1;
Field[2].SizeMin = h_fine; Field[2].SizeMax = h_coarse; Field[2].DistMin = 1; Field[2].DistMax = 10;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0; Mesh.MeshSizeFromPoints = 0; Mesh.MeshSizeFromCurvature = 0;

Physical Surface("aluminium") = {1};
Physical Surface("steel") = {2};
Physical Curve("aluminium_base") = {3};
Physical Curve("aluminium_arc") = {1, 2};
Physical Curve("steel_top") = {13};
Physical Curve("steel_arc") = {11, 12};
