/*
 * jointrom_sundials.h: the parts of SUNDIALS 6.4 that sundials-sys 0.6 leaves out, plus
 * jointrom's own small C shim (jointrom_sundials.c). build.rs runs bindgen on this header and
 * keeps only the items declared in the files included below (everything else, such as
 * N_Vector or sunindextype, comes from sundials-sys, so the types stay compatible).
 *
 * sundials-sys 0.6.2's wrapper.h already covers nvector_serial, the band/dense/sparse
 * matrices, all serial linear solvers, the fixed-point and Newton nonlinear solvers and
 * cvode.h (which includes cvode_ls.h and cvode_proj.h). It lacks:
 *   - sundials_version.h: the run-time version of the library actually linked;
 *   - cvode_diag.h:       CVDiag, CVODE's diagonal approximate-Jacobian linear solver;
 *   - cvode_bandpre.h:    CVBandPrecInit, the banded difference-quotient preconditioner;
 *   - arkode_arkstep.h:   ARKODE's ARKStep (additive Runge-Kutta) integrator with the
 *                         ARKODE core (arkode.h), its linear-solver interface (arkode_ls.h)
 *                         and the Butcher tables (arkode_butcher*.h): the implicit (DIRK)
 *                         alternative to CVODE's BDF.
 * The version macros (SUNDIALS_VERSION_MAJOR/MINOR/PATCH of sundials_config.h) are
 * exported by sundials-sys too; they are generated here again so that the crate can check
 * at compile time that both binding runs saw the same SUNDIALS.
 */
#ifndef JOINTROM_SUNDIALS_H
#define JOINTROM_SUNDIALS_H

#include <sundials/sundials_config.h>
#include <sundials/sundials_types.h>
#include <sundials/sundials_version.h>
#include <cvode/cvode_diag.h>
#include <cvode/cvode_bandpre.h>
#include <arkode/arkode_arkstep.h>

#ifdef __cplusplus
extern "C" {
#endif

/*
 * Version of the SUNDIALS library linked at run time (SUNDIALSGetVersionNumber with a label
 * buffer large enough for any label). Returns 0 on success, a negative value otherwise.
 */
int jointrom_sundials_library_version(int *major, int *minor, int *patch);

/*
 * Frees a string returned by a SUNDIALS *GetReturnFlagName function (CVODE allocates it with
 * malloc and leaves freeing it to the caller). Null is allowed.
 */
void jointrom_sundials_free_string(char *name);

#ifdef __cplusplus
}
#endif

#endif /* JOINTROM_SUNDIALS_H */
