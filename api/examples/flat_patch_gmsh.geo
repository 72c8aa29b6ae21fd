// flat_patch.json in Gmsh form: two blocks [0, 2] x [-1, 0] and [0, 2] x [0, 1] pressed together, meshed in
// triangles of different sizes (non-matching along y = 0). The contact pressure is uniform and the P1 elements
// reproduce the linear displacement field, so the solution is exact on any mesh.
// Generated into flat_patch_gmsh.msh by scripts/make_gmsh_examples.sh.
SetFactory("Built-in");
Geometry.AutoCoherence = 0;  // the blocks touch along y = 0 but must keep their own nodes

h_lower = 0.3; h_upper = 0.23;
Point(1) = {0, -1, 0, h_lower}; Point(2) = {2, -1, 0, h_lower}; Point(3) = {2, 0, 0, h_lower}; Point(4) = {0, 0, 0, h_lower};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Point(5) = {0, 0, 0, h_upper}; Point(6) = {2, 0, 0, h_upper}; Point(7) = {2, 1, 0, h_upper}; Point(8) = {0, 1, 0, h_upper};
Line(5) = {5, 6}; Line(6) = {6, 7}; Line(7) = {7, 8}; Line(8) = {8, 5};
Curve Loop(2) = {5, 6, 7, 8}; Plane Surface(2) = {2};

Physical Surface("lower") = {1};
Physical Surface("upper") = {2};
Physical Curve("lower_bottom") = {1};
Physical Curve("lower_top") = {3};
Physical Curve("upper_bottom") = {5};
Physical Curve("upper_top") = {7};
Physical Curve("left") = {4, 8};  // the symmetry line x = 0: one curve on both bodies
