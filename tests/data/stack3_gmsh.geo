// Three blocks stacked in one file, [0, 2] x [-1, 0], [0, 1] and [1, 2], the middle one meshed fine (hf) so that
// the file's text is a few MB: tests/server/test_meshes_table.py meshes it with `gmsh -2 ... -format msh41`
// and sends three bodies of it through contactd. Pressed together along y with every side but x = 0 free, the
// stack is in uniaxial compression: the contact pressure is uniform, exact on any mesh (P1 holds the linear field).
SetFactory("Built-in");
Geometry.AutoCoherence = 0;
h = 0.25;
DefineConstant[ hf = 0.008 ];  // the middle block's element size: 36,555 nodes, 3.4 MB of text
Point(1) = {0, -1, 0, h}; Point(2) = {2, -1, 0, h}; Point(3) = {2, 0, 0, h}; Point(4) = {0, 0, 0, h};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Point(5) = {0, 0, 0, hf}; Point(6) = {2, 0, 0, hf}; Point(7) = {2, 1, 0, hf}; Point(8) = {0, 1, 0, hf};
Line(5) = {5, 6}; Line(6) = {6, 7}; Line(7) = {7, 8}; Line(8) = {8, 5};
Curve Loop(2) = {5, 6, 7, 8}; Plane Surface(2) = {2};
Point(9) = {0, 1, 0, h}; Point(10) = {2, 1, 0, h}; Point(11) = {2, 2, 0, h}; Point(12) = {0, 2, 0, h};
Line(9) = {9, 10}; Line(10) = {10, 11}; Line(11) = {11, 12}; Line(12) = {12, 9};
Curve Loop(3) = {9, 10, 11, 12}; Plane Surface(3) = {3};
Physical Surface("lower") = {1}; Physical Surface("middle") = {2}; Physical Surface("upper") = {3};
Physical Curve("lower_bottom") = {1}; Physical Curve("lower_top") = {3};
Physical Curve("middle_bottom") = {5}; Physical Curve("middle_top") = {7};
Physical Curve("upper_bottom") = {9}; Physical Curve("upper_top") = {11};
Physical Curve("left") = {4, 8, 12};
