# MuJoCo beside the solvers (bench_mujoco.cpp, docs/benchmarks.md "Peers in the
# same run"): when CMake finds it (Debian libmujoco-dev), the suite times
# mj_forward on the same URDFs, constraints and states as algorithm "mujoco".
# Included from bench/CMakeLists.txt after proxgen_bench_support (needs have_cases).
find_package(mujoco QUIET)
if(have_cases AND mujoco_FOUND)
  message(STATUS "bench: MuJoCo ${mujoco_VERSION} found: the suite times it as 'mujoco'")
  # Debian 12's config lists /usr/include/libqhull_r/, which only libqhull-dev
  # installs and MuJoCo's public headers do not need: keep the directories that exist.
  get_target_property(mujoco_dirs mujoco::mujoco INTERFACE_INCLUDE_DIRECTORIES)
  list(FILTER mujoco_dirs INCLUDE REGEX ".")
  set(mujoco_existing "")
  foreach(dir IN LISTS mujoco_dirs)
    if(EXISTS "${dir}")
      list(APPEND mujoco_existing "${dir}")
    endif()
  endforeach()
  set_target_properties(mujoco::mujoco PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${mujoco_existing}")
  target_sources(proxgen_bench_support PRIVATE bench_mujoco.cpp)
  target_link_libraries(proxgen_bench_support PRIVATE mujoco::mujoco PkgConfig::TINYXML2)
  string(APPEND peer_decls "std::unique_ptr<Solver> makeMujocoSolver(const BenchCase&);\n")
  string(APPEND peer_entries "      {\"mujoco\", &makeMujocoSolver},\n")
else()
  message(STATUS "bench: MuJoCo not found (libmujoco-dev): no MuJoCo in the suite")
endif()
