// The whole runtime in one translation unit (easy to vendor). Standard library only.
#include "quiver/quiver.h"

#define QV_STR2(x) #x
#define QV_STR(x) QV_STR2(x)

extern "C" {

const char* qv_version_string(void) {
  return QV_STR(QV_VERSION_MAJOR) "." QV_STR(QV_VERSION_MINOR) "." QV_STR(QV_VERSION_PATCH);
}

int qv_check_version(int version_number) { return version_number == QV_VERSION_NUMBER; }

}
