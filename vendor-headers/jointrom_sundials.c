/*
 * jointrom_sundials.c: jointrom's C shim over SUNDIALS 6.4 (compiled by build.rs with cc).
 * The static assertions check, with the C compiler and the same headers, the assumptions
 * the Rust side makes: SUNDIALS 6, sunrealtype = double, sunindextype = 64-bit integer.
 */
#include <stdint.h>
#include <stdlib.h>

#include "jointrom_sundials.h"

_Static_assert(SUNDIALS_VERSION_MAJOR == 6,
               "jointrom needs SUNDIALS 6.x headers (Debian bookworm: libsundials-dev)");
_Static_assert(sizeof(sunrealtype) == sizeof(double),
               "jointrom needs SUNDIALS built in double precision");
_Static_assert(sizeof(sunindextype) == sizeof(int64_t),
               "jointrom needs SUNDIALS built with 64-bit indices");

int jointrom_sundials_library_version(int *major, int *minor, int *patch)
{
  /* SUNDIALSGetVersionNumber fails (without writing anything) if the label does not fit. */
  char label[256];
  if (major == NULL || minor == NULL || patch == NULL) return -1;
  return SUNDIALSGetVersionNumber(major, minor, patch, label, (int)sizeof label);
}

void jointrom_sundials_free_string(char *name)
{
  free(name);
}
