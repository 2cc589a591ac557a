/* Build-time configuration of the Quiver runtime. Define QV_USER_CONFIG as "my_file.h" to
   override any of these from your own header without editing this one. */
#ifndef QUIVER_CONFIG_H
#define QUIVER_CONFIG_H

#ifdef QV_USER_CONFIG
#include QV_USER_CONFIG
#endif

/* QV_ASSERT(x): internal consistency checks; off in release builds unless you define it. */
#ifndef QV_ASSERT
#include <assert.h>
#define QV_ASSERT(x) assert(x)
#endif

/* QV_API: export attribute for the C API (e.g. __declspec(dllexport) when building a DLL). */
#ifndef QV_API
#define QV_API
#endif

#endif
