// The whole runtime in one translation unit (easy to vendor: this folder plus formats/model/).
// Standard library only.
#include "quiver/quiver.h"

#include "model.cpp"
#include "reduced_polynomial.cpp"
#include "instance.cpp"

#define QV_STR2(x) #x
#define QV_STR(x) QV_STR2(x)

extern "C" {

const char* qv_version_string(void) {
  return QV_STR(QV_VERSION_MAJOR) "." QV_STR(QV_VERSION_MINOR) "." QV_STR(QV_VERSION_PATCH);
}

int qv_check_version(int version_number, size_t model_info_size, size_t instance_config_size) {
  return version_number == QV_VERSION_NUMBER && model_info_size == sizeof(qv_model_info) &&
         instance_config_size == sizeof(qv_instance_config);
}

const char* qv_result_string(qv_result result) {
  switch (result) {
    case QV_OK: return "ok";
    case QV_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case QV_ERROR_IO: return "input/output error";
    case QV_ERROR_FORMAT: return "invalid model file";
    case QV_ERROR_OUT_OF_MEMORY: return "out of memory";
  }
  return "unknown result";
}

}
