/* Compiled by the C compiler with -std=c99 -Wall -Wextra -Werror -pedantic
   (tests/c_api/CMakeLists.txt): quadruped_c.h is C99. */
#include "c_calls.h"

#include <stdlib.h>

/* A caller-provided buffer of quadruped_WORK_SIZE bytes, aligned for double
   (quadruped_WORK_ALIGN): the union gives it double's alignment. */
static union {
  double align;
  unsigned char bytes[quadruped_WORK_SIZE];
} buffer;

size_t c_work_size(void) { return quadruped_work_size(); }
size_t c_work_align(void) { return quadruped_work_align(); }

void c_call_all(const double* q, const double* v, const double* tau, const double* qdd, const double* lambda, double mu,
                int iterations, const unsigned char* active, const double* lambda0, struct c_results* out) {
  void* work = buffer.bytes;
  if (quadruped_work_size() != sizeof buffer.bytes || quadruped_work_align() > sizeof(double)) abort();
  quadruped_constrained_aba(q, v, tau, mu, iterations, active, lambda0, work, out->caba_qdd, out->caba_lambda);
  out->caba_residual = quadruped_residual(work);
  quadruped_prox_pv(q, v, tau, mu, iterations, active, lambda0, work, out->pv_qdd, out->pv_lambda);
  out->pv_residual = quadruped_residual(work);
  quadruped_inverse_dynamics(q, v, qdd, lambda, active, work, out->tau);
  quadruped_nonlinear_effects(q, v, work, out->h);
  quadruped_mass_matrix(q, work, out->M);
  quadruped_mass_matrix_inverse(q, work, out->Minv);
  quadruped_constraint_placements(q, work, out->X);
  quadruped_constraint_jacobian(q, active, work, out->J);
  quadruped_constraint_drift(q, v, active, work, out->gamma);
  quadruped_delassus(q, active, work, out->G);
  quadruped_delassus_inverse(q, mu, active, work, out->Ginv);
  quadruped_constraint_wrenches(q, lambda, work, out->W);
}

/* ---- The README's C controller loop, as printed there (between the markers). */
/* README-C-BEGIN */
#include "quadruped_c.h"

static double work[quadruped_WORK_SIZE / sizeof(double)]; /* the buffer: double-aligned */
static double lambda[quadruped_NC];                      /* kept between steps: the warm start */
static unsigned char active[quadruped_NCONS] = {1, 1, 1, 1};

/* One step: W gets each foot's wrench on the robot (world axes). */
static void step(const double* q, const double* v, const double* tau, int lf_in_swing, double* qdd,
                 double W[6 * quadruped_NCONS]) {
  active[quadruped_CONSTRAINT_lf_foot] = !lf_in_swing;  /* contact schedule */
  quadruped_prox_pv(q, v, tau, 1e4, 2, active, lambda, work, qdd, lambda); /* warm start */
  if (quadruped_residual(work) > 1e-6)                       /* not accurate enough: 8 more */
    quadruped_prox_pv(q, v, tau, 1e4, 8, active, lambda, work, qdd, lambda);
  quadruped_constraint_wrenches(q, lambda, work, W);         /* W + 6 k: force, torque of foot k */
}
/* README-C-END */

void c_controller(const double* q, const double* v, const double* tau, int steps, double* qdd, double* lambda_out,
                  double* residual, double* W) {
  int k;
  for (k = 0; k < quadruped_NC; ++k) lambda[k] = 0;
  for (k = 0; k < quadruped_NCONS; ++k) active[k] = 1;
  for (k = 0; k < steps; ++k) step(q, v, tau, k % 2, qdd, W);
  for (k = 0; k < quadruped_NC; ++k) lambda_out[k] = lambda[k];
  *residual = quadruped_residual(work);
}
