#pragma once
// Owned HDF5 identifiers and error reporting for the archive: a Handle closes its hid_t with the
// H5?close of its kind, and Where turns a failed HDF5 call into std::runtime_error
// "FILE: OBJECT: what failed (HDF5's most specific reason)". Callers turn HDF5's automatic
// error printing off (H5Eset_auto2), so nothing is printed.
#include <stdexcept>
#include <string>
#include <utility>

#include <hdf5.h>

namespace quiver::hdf5 {

class Handle {
public:
  using Close = herr_t (*)(hid_t);
  Handle(hid_t id, Close close) : id_(id), close_(close) {}
  Handle(Handle&& other) noexcept : id_(std::exchange(other.id_, H5I_INVALID_HID)), close_(other.close_) {}
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle& operator=(Handle&&) = delete;
  ~Handle() {
    if (id_ >= 0) close_(id_);
  }
  hid_t get() const { return id_; }

private:
  hid_t id_;
  Close close_;
};

// The file and object an operation is about.
struct Where {
  std::string file;
  std::string object;

  [[noreturn]] void fail(const std::string& what) const {
    std::string reason;
    H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, innermostReason, &reason);
    H5Eclear2(H5E_DEFAULT);
    throw std::runtime_error(file + ": " + object + ": " + what + (reason.empty() ? "" : " (" + reason + ")"));
  }
  // Returns `result`, or fails with `what` when it is negative (HDF5's error convention).
  template <class T>
  T check(T result, const std::string& what) const {
    if (result < 0) fail(what);
    return result;
  }
  Handle own(hid_t id, Handle::Close close, const std::string& what) const { return Handle(check(id, what), close); }

private:
  // The walk starts at the most specific entry of HDF5's error stack: keep that one.
  static herr_t innermostReason(unsigned n, const H5E_error2_t* error, void* reason) {
    if (n == 0 && error->desc) *static_cast<std::string*>(reason) = error->desc;
    return 0;
  }
};

} // namespace quiver::hdf5
