#pragma once
// Owning handles for PETSc/SLEPc objects, so that an exception in the middle of a stage cannot
// leak them, and PetscCall-style checking that throws instead of returning codes.
#include <stdexcept>
#include <string>

#include <petsclog.h>
#include <petscsys.h>

namespace quiver {

// Throws std::runtime_error naming the call when a PETSc/SLEPc function fails.
inline void petscCheck(PetscErrorCode code, const char* call) {
  if (code == 0) return;
  const char* text = nullptr;
  PetscErrorMessage(code, &text, nullptr);
  throw std::runtime_error(std::string(call) + " failed: " + (text ? text : "PETSc error " + std::to_string(code)));
}
#define QV_PETSC(call) ::quiver::petscCheck((call), #call)

// Owns one PETSc object of type T (Mat, Vec, KSP, EPS, ...), destroyed with `Destroy`.
template <class T, PetscErrorCode (*Destroy)(T*)>
class PetscHandle {
public:
  PetscHandle() = default;
  explicit PetscHandle(T object) : object_(object) {}
  ~PetscHandle() { reset(); }
  PetscHandle(PetscHandle&& other) noexcept : object_(other.object_) { other.object_ = nullptr; }
  PetscHandle& operator=(PetscHandle&& other) noexcept {
    if (this != &other) {
      reset();
      object_ = other.object_;
      other.object_ = nullptr;
    }
    return *this;
  }
  PetscHandle(const PetscHandle&) = delete;
  PetscHandle& operator=(const PetscHandle&) = delete;

  T get() const { return object_; }
  operator T() const { return object_; }  // NOLINT: pass straight to PETSc calls
  T* out() {  // for PETSc's create functions
    reset();
    return &object_;
  }
  void reset() {
    if (object_) Destroy(&object_);
    object_ = nullptr;
  }

private:
  T object_ = nullptr;
};

// A -log_view row of our own, under the class `className`. Register each once per process (keep
// it in a function-local static).
inline PetscLogEvent registerLogEvent(const char* className, const char* eventName) {
  PetscClassId id = 0;
  PetscLogEvent event = 0;
  PetscClassIdRegister(className, &id);
  PetscLogEventRegister(eventName, id, &event);
  return event;
}

// Times its scope as `event` (ended on exceptions too).
class LogEventScope {
public:
  explicit LogEventScope(PetscLogEvent event) : event_(event) { PetscLogEventBegin(event_, 0, 0, 0, 0); }
  ~LogEventScope() { PetscLogEventEnd(event_, 0, 0, 0, 0); }
  LogEventScope(const LogEventScope&) = delete;
  LogEventScope& operator=(const LogEventScope&) = delete;

private:
  PetscLogEvent event_;
};

} // namespace quiver
