/* The C side of tests/c_api/test_c_api.cpp: every function of quadruped_c.h
   called from C (c_calls.c), its outputs gathered for the C++ side to compare
   with the C++ API's. C and C++ both include this header. */
#ifndef PROXGEN_TEST_C_CALLS_H
#define PROXGEN_TEST_C_CALLS_H

#include "quadruped_c.h"

#ifdef __cplusplus
extern "C" {
#endif

struct c_results {
  double caba_qdd[quadruped_NV], caba_lambda[quadruped_NC], caba_residual;
  double pv_qdd[quadruped_NV], pv_lambda[quadruped_NC], pv_residual;
  double tau[quadruped_NV], h[quadruped_NV], M[quadruped_NV * quadruped_NV], Minv[quadruped_NV * quadruped_NV];
  double X[12 * quadruped_NCONS], J[quadruped_NC * quadruped_NV], gamma[quadruped_NC];
  double G[quadruped_NC * quadruped_NC], Ginv[quadruped_NC * quadruped_NC], W[6 * quadruped_NCONS];
};

/* quadruped_work_size() and quadruped_work_align(), as C sees them. */
size_t c_work_size(void);
size_t c_work_align(void);

/* Every wrapped function once, in a buffer of quadruped_work_size() bytes:
   the solvers with (mu, iterations, active, lambda0), inverse_dynamics with
   (qdd, lambda, active), the constraint functions with active, constraint_wrenches
   with lambda, delassus_inverse with (mu, active). */
void c_call_all(const double* q, const double* v, const double* tau, const double* qdd, const double* lambda, double mu,
                int iterations, const unsigned char* active, const double* lambda0, struct c_results* out);

/* The README's C controller loop (README.md, "The generated solver"): `steps`
   steps from (q, v, tau), the left front foot lifted on the odd ones; the last
   step's qdd, lambda, residual and wrenches. */
void c_controller(const double* q, const double* v, const double* tau, int steps, double* qdd, double* lambda,
                  double* residual, double* W);

#ifdef __cplusplus
}
#endif

#endif
