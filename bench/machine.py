"""What every bench figure is printed with: the CPU it ran on and the BLAS kernels in use."""
import ctypes


def cpu_model():
    """The CPU's model name as /proc/cpuinfo gives it."""
    with open("/proc/cpuinfo") as f:
        return next((line.split(":", 1)[1].strip() for line in f if line.startswith("model name")), "?")


def blas_core():
    """The kernel set Debian's OpenBLAS chose on this CPU (OPENBLAS_CORETYPE overrides it)."""
    try:
        lib = ctypes.CDLL("libopenblas.so.0")
        lib.openblas_get_corename.restype = ctypes.c_char_p
        return lib.openblas_get_corename().decode()
    except OSError:
        return "? (libopenblas.so.0 not found)"


def machine_line():
    return f"CPU: {cpu_model()}; OpenBLAS core: {blas_core()}"
