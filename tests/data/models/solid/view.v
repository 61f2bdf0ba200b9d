// The 3D geometry's tests (tests/it/solid.rs).
line style: cylinder
contour sides: 6
capped cylinders: on
surface: leaf.s 2 4 2
