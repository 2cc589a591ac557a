/* Quiver runtime: real-time reduced St.Venant-Kirchhoff deformables. C API.
   The simulation API (qv_model, qv_instance, qv_step) arrives with the runtime issue; this
   header already fixes the conventions: qv_ prefix, plain C types, no exceptions. */
#ifndef QUIVER_H
#define QUIVER_H

#include "quiver/quiver_config.h"

#ifdef __cplusplus
extern "C" {
#endif

#define QV_VERSION_MAJOR 0
#define QV_VERSION_MINOR 1
#define QV_VERSION_PATCH 0
#define QV_VERSION_NUMBER (QV_VERSION_MAJOR * 10000 + QV_VERSION_MINOR * 100 + QV_VERSION_PATCH)

/* The library's version as "major.minor.patch". */
QV_API const char* qv_version_string(void);

/* Non-zero when the library this program links was built from the headers it was compiled
   with (same version number); call once at start-up as QV_CHECK_VERSION(). */
QV_API int qv_check_version(int version_number);
#define QV_CHECK_VERSION() qv_check_version(QV_VERSION_NUMBER)

#ifdef __cplusplus
}
#endif

#endif
