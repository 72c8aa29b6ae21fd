// A flat punch with rounded corners (radius 0.1) pressed on a block: the punch.json problem without the
// corner singularity. Lengths in cm. Mesh: triangles, 0.01 along the punch's bottom, coarser away from it.
// Generated into punch_rounded_gmsh.msh by scripts/make_gmsh_examples.sh (gmsh -2 ... -format msh41).
SetFactory("Built-in");
Geometry.AutoCoherence = 0;  // the punch and the block touch along y = 0 but must keep their own nodes

r = 0.1;        // corner radius
h_fine = 0.01;  // along the contact
h_punch = 0.05; h_block = 0.2;

// Block [-2, 2] x [-1, 0]; its top is split where the punch's flat part and corners sit above it.
Point(1) = {-2, -1, 0, h_block}; Point(2) = {2, -1, 0, h_block};
Point(3) = {2, 0, 0, h_block};   Point(4) = {0.7, 0, 0, h_fine};
Point(5) = {-0.7, 0, 0, h_fine}; Point(6) = {-2, 0, 0, h_block};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 6}; Line(6) = {6, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6}; Plane Surface(1) = {1};

// Punch [-0.5, 0.5] x [0, 0.5], bottom corners rounded.
Point(11) = {-0.5 + r, 0, 0, h_fine}; Point(12) = {0.5 - r, 0, 0, h_fine};
Point(13) = {0.5, r, 0, h_fine};      Point(14) = {0.5, 0.5, 0, h_punch};
Point(15) = {-0.5, 0.5, 0, h_punch};  Point(16) = {-0.5, r, 0, h_fine};
Point(17) = {0.5 - r, r, 0};          Point(18) = {-0.5 + r, r, 0};  // corner centres
Line(11) = {11, 12}; Circle(12) = {12, 17, 13}; Line(13) = {13, 14}; Line(14) = {14, 15}; Line(15) = {15, 16};
Circle(16) = {16, 18, 11};
Curve Loop(2) = {11, 12, 13, 14, 15, 16}; Plane Surface(2) = {2};

Physical Surface("block") = {1};
Physical Surface("punch") = {2};
Physical Curve("block_bottom") = {1};
Physical Curve("block_top") = {3, 4, 5};
Physical Curve("punch_bottom") = {16, 11, 12};
Physical Curve("punch_top") = {14};
