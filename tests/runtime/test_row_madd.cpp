// row_madd and row_product in the lanes of the build's own flags (at the x86-64
// baseline: 2 doubles a vector): row_madd_checks.inc.
#include "row_madd_checks.inc"
