// A unit cube meshed coarsely by gmsh, for the reader tests in tests/data/:
//   gmsh -3 box.geo -format msh22 -o ../../tests/data/gmsh_box_v2.msh
//   gmsh -3 box.geo -format msh41 -o ../../tests/data/gmsh_box_v4.msh
// The face x = 0 is physical surface 1, x = 1 is 2; the other faces have no physical
// group, so gmsh does not write their triangles (their boundary id is 0).
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 1};
Physical Surface(1) = {1};
Physical Surface(2) = {2};
Physical Volume(10) = {1};
Mesh.MeshSizeMin = 0.5;
Mesh.MeshSizeMax = 0.5;
Mesh.Binary = 0;
