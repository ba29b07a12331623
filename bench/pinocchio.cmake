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
  # Eigen's alignment is part of Pinocchio's ABI: its library (the URDF parser
  # builds the Model) was compiled with one, and these headers must assume the
  # same. With PROXGEN_MARCH=native on an AVX-512 machine Eigen would assume 64
  # bytes where a Pinocchio built for the x86-64 baseline allocated with 16, and
  # the first aligned load crashes (initPvSolver, 2026-12-06). 16 matches such a
  # Pinocchio; 0 leaves Eigen's default (a Pinocchio built with the same -march).
  set(PROXGEN_BENCH_PINOCCHIO_EIGEN_ALIGN 16 CACHE STRING
      "EIGEN_MAX_ALIGN_BYTES for bench_pinocchio.cpp when PROXGEN_MARCH is set: the alignment Pinocchio's library was built with (16: the x86-64 baseline; 0: Eigen's default)")
  if(PROXGEN_MARCH AND NOT PROXGEN_BENCH_PINOCCHIO_EIGEN_ALIGN STREQUAL "0")
    if(NOT PROXGEN_BENCH_PINOCCHIO_EIGEN_ALIGN MATCHES "^(16|32|64)$")
      message(FATAL_ERROR "PROXGEN_BENCH_PINOCCHIO_EIGEN_ALIGN='${PROXGEN_BENCH_PINOCCHIO_EIGEN_ALIGN}': 0, 16, 32 or 64")
    endif()
    set_source_files_properties(bench_pinocchio.cpp PROPERTIES COMPILE_DEFINITIONS
      "EIGEN_MAX_ALIGN_BYTES=${PROXGEN_BENCH_PINOCCHIO_EIGEN_ALIGN};EIGEN_MAX_STATIC_ALIGN_BYTES=${PROXGEN_BENCH_PINOCCHIO_EIGEN_ALIGN}")
    message(STATUS "bench: Pinocchio's headers with -march=${PROXGEN_MARCH} and Eigen's alignment at "
                   "${PROXGEN_BENCH_PINOCCHIO_EIGEN_ALIGN} bytes (PROXGEN_BENCH_PINOCCHIO_EIGEN_ALIGN)")
  endif()
  string(APPEND peer_decls "std::unique_ptr<Solver> makePinocchioCaba(const BenchCase&);\n"
                           "std::unique_ptr<Solver> makePinocchioPv(const BenchCase&);\n")
  string(APPEND peer_entries "      {\"pin_caba\", &makePinocchioCaba},\n      {\"pin_pv\", &makePinocchioPv},\n")
else()
  message(STATUS "bench: Pinocchio 3.7 not found (set CMAKE_PREFIX_PATH to an install): no Pinocchio in the suite")
endif()
