# The fuzz targets: one list, included by tests/fuzz/CMakeLists.txt (which builds fuzz_<name>) and
# tests/CMakeLists.txt (which runs each as the test fuzz.<name> from the seeds in seeds/<name>/).
# The mesh readers share fuzz_mesh_reader.cpp, which picks its reader from QUIVER_FUZZ_FORMAT: the
# 1-based position in QUIVER_FUZZ_MESH_READERS (the QUIVER_FUZZ_* numbers in that file).
set(QUIVER_FUZZ_MESH_READERS gmsh medit mfem vega vtk vtu tetgen bou)
set(QUIVER_FUZZ_TARGETS ${QUIVER_FUZZ_MESH_READERS} npy qvr surface drag_script scenario snapshot)
