"""What every bench figure is printed with: the CPU it ran on and the BLAS kernels in use."""
import ctypes


def cpu_model():
    """The CPU's model name as /proc/cpuinfo gives it, with its family and model numbers and its widest
    vectors: a virtual machine's name ("AMD EPYC") can stand for CPUs of different generations."""
    fields = {}
    with open("/proc/cpuinfo") as f:
        for line in f:
            if not line.strip():
                break
            key, _, value = line.partition(":")
            fields[key.strip()] = value.strip()
    flags = fields.get("flags", "").split()
    vectors = "AVX-512" if "avx512f" in flags else "AVX2" if "avx2" in flags else "SSE"
    return (f"{fields.get('model name', '?')} (family {fields.get('cpu family', '?')} model {fields.get('model', '?')}, "
            f"{vectors})")


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
