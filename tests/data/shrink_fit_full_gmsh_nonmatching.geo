// The shrink fit of shrink_fit_full_gmsh.geo on NON-matching meshes (tests/integration/test_curved_contact.cpp): a solid shaft
// of radius a = 500 in a ring a .. b = 1000, one closed physical curve per body round the interface ("rim" on the
// shaft, "bore" on the ring), the shaft's cut into 4 n_shaft arcs and the ring's into 4 n_ring, so no node but the
// four on the axes is shared. The supports as in shrink_fit_full_gmsh.geo. Generated, coarse and fine, by
//   gmsh -2 shrink_fit_full_gmsh_nonmatching.geo -format msh41 -setnumber n_shaft 24 -setnumber n_ring 32 \
//        -setnumber h_out 80 -o shrink_fit_full_gmsh_24_32.msh
//   gmsh -2 shrink_fit_full_gmsh_nonmatching.geo -format msh41 -setnumber n_shaft 48 -setnumber n_ring 64 \
//        -setnumber h_out 40 -o shrink_fit_full_gmsh_48_64.msh
SetFactory("Built-in");
Geometry.AutoCoherence = 0;  // the bodies touch along r = a but must keep their own nodes

a = 500; b = 1000;
If (!Exists(n_shaft)) n_shaft = 24; EndIf  // arcs per quarter of the shaft's rim
If (!Exists(n_ring)) n_ring = 32; EndIf    // arcs per quarter of the ring's bore
If (!Exists(h_out)) h_out = 80; EndIf      // the size away from the interface
h_shaft = 2 * Pi * a / (4 * n_shaft);
h_ring = 2 * Pi * a / (4 * n_ring);

// Shaft: the disk r <= a, its centre a node.
Point(1) = {0, 0, 0, h_out};
Point(2) = {a, 0, 0, h_shaft}; Point(3) = {0, a, 0, h_shaft}; Point(4) = {-a, 0, 0, h_shaft}; Point(5) = {0, -a, 0, h_shaft};
Circle(1) = {2, 1, 3}; Circle(2) = {3, 1, 4}; Circle(3) = {4, 1, 5}; Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Point{1} In Surface{1};

// Ring: a <= r <= b.
Point(11) = {0, 0, 0, h_out};
Point(12) = {a, 0, 0, h_ring}; Point(13) = {0, a, 0, h_ring}; Point(14) = {-a, 0, 0, h_ring}; Point(15) = {0, -a, 0, h_ring};
Point(16) = {b, 0, 0, h_out}; Point(17) = {0, b, 0, h_out}; Point(18) = {-b, 0, 0, h_out}; Point(19) = {0, -b, 0, h_out};
Circle(11) = {12, 11, 13}; Circle(12) = {13, 11, 14}; Circle(13) = {14, 11, 15}; Circle(14) = {15, 11, 12};
Circle(15) = {16, 11, 17}; Circle(16) = {17, 11, 18}; Circle(17) = {18, 11, 19}; Circle(18) = {19, 11, 16};
Curve Loop(2) = {15, 16, 17, 18};
Curve Loop(3) = {11, 12, 13, 14};
Plane Surface(2) = {2, 3};

Transfinite Curve{1, 2, 3, 4} = n_shaft + 1;
Transfinite Curve{11, 12, 13, 14} = n_ring + 1;
Recombine Surface{2};  // the ring in quadrangles (and a few triangles)

Physical Surface("shaft") = {1};
Physical Surface("ring") = {2};
Physical Curve("rim") = {1, 2, 3, 4};
Physical Curve("bore") = {11, 12, 13, 14};
Physical Curve("outside") = {15, 16, 17, 18};
Physical Point("centre") = {1};
Physical Point("shaft_east") = {2};
Physical Point("ring_east") = {16};
Physical Point("ring_north") = {17};
Physical Point("ring_west") = {18};
