// Test vectors of one case, written on the host by proxgen_make_vectors
// (tests/embedded/host/make_vectors.cpp) as vectors_<case>.cpp: fixed states and the generic
// solvers' answers in double. Compiled in the firmware's scalar: define PROXGEN_VECTORS_FLOAT=1
// for float, so every literal is rounded once, from 17 digits, to the scalar the solver uses.
#pragma once

namespace proxgen_vectors {

#if PROXGEN_VECTORS_FLOAT
using Real = float;
#define PROXGEN_R(x) x##f
#else
using Real = double;
#define PROXGEN_R(x) x
#endif

enum class Algorithm : int { constrained_aba = 0, prox_pv = 1 };

// One reference answer: the generic solver `algorithm` at (mu, iterations) on state `state`.
struct Result {
  int state;
  Algorithm algorithm;
  Real mu;
  int iterations;
  Real reference;      // round-off bound of qdd, lambda (computed in double) / double epsilon
  Real conditioning;   // kappa_s(M) + kappa_s(G) at the state, Jacobi-scaled (tests/numerics.hpp)
  const Real* qdd;     // nv
  const Real* lambda;  // nc, layout order
};

struct Case {
  const char* name;
  int nq, nv, nc;
  Real mu;                 // the layout's mu
  Real light_mass;         // lightest body on the constraint support (kg) ...
  const char* light_link;  // ... and its link
  int num_states;
  const Real* q;    // num_states x nq
  const Real* v;    // num_states x nv
  const Real* tau;  // num_states x nv
  int num_results;
  const Result* results;
};

extern const Case test_case;

}  // namespace proxgen_vectors
