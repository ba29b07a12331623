# Pinocchio beside the solvers (bench_pinocchio.cpp, docs/benchmarks.md "Peers in
# the same run"): when CMake finds Pinocchio 3.7 or later installed (never part of
# the repository: point CMAKE_PREFIX_PATH at an install), the suite times its
# constraintDynamics and pv on the same cases and states as "pin_caba", "pin_pv".
# Included from bench/CMakeLists.txt after proxgen_bench_support (needs have_cases).
find_package(pinocchio 3.7 QUIET)
if(have_cases AND pinocchio_FOUND)
  message(STATUS "bench: Pinocchio ${pinocchio_VERSION} found: the suite times it as 'pin_caba', 'pin_pv'")
  target_sources(proxgen_bench_support PRIVATE bench_pinocchio.cpp)
  target_link_libraries(proxgen_bench_support PRIVATE pinocchio::pinocchio)
  string(APPEND peer_decls "std::unique_ptr<Solver> makePinocchioCaba(const BenchCase&);\n"
                           "std::unique_ptr<Solver> makePinocchioPv(const BenchCase&);\n")
  string(APPEND peer_entries "      {\"pin_caba\", &makePinocchioCaba},\n      {\"pin_pv\", &makePinocchioPv},\n")
else()
  message(STATUS "bench: Pinocchio 3.7 not found (set CMAKE_PREFIX_PATH to an install): no Pinocchio in the suite")
endif()
