// sincos_run and sincos_joint in the mode of the build's own flags (at the
// x86-64 baseline: each joint computes its own): sincos_run_checks.inc.
#include "sincos_run_checks.inc"
