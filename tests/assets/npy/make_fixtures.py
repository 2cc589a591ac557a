#!/usr/bin/python3
"""Writes the .npy files that tests/formats/npy_test.cpp reads, with numpy's own writer. The test
types the same values as literals; change both together. Re-run after changing it:
/usr/bin/python3 tests/assets/npy/make_fixtures.py"""
import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def save(name, array, version=None):
    with open(os.path.join(HERE, name), "wb") as f:
        np.lib.format.write_array(f, array, version=version)


def main():
    # 3x2 float64 in C order, with a negative zero and the smallest denormal.
    save("c_order_3x2.npy", np.array([[1.5, -2.25], [3.0, 0.1], [-0.0, 5e-324]]))
    # 3x2 float64 in Fortran order: the file holds the columns 1, 3, 5 then 2, 4, 6 (times 1.25).
    fortran = np.asfortranarray(np.array([[1.0, 2.0], [3.0, 4.0], [5.0, 6.0]]) * 1.25)
    assert fortran.flags.f_contiguous and not fortran.flags.c_contiguous
    save("fortran_3x2.npy", fortran)
    # float32 vector: 0.1 rounded to float32, the largest float32, the smallest float32 denormal.
    save("float32_vector.npy", np.array([0.1, -1.5, 3.4028234663852886e38, 1e-45], dtype="<f4"))
    # Big-endian float64, 2x2.
    save("big_endian_2x2.npy", np.array([[1.0, -2.5], [np.inf, 1e300]], dtype=">f8"))
    # Format versions 2.0 and 3.0 (4-byte header length) of the same vector.
    save("version2.npy", np.arange(4.0) * 0.5, version=(2, 0))
    save("version3.npy", np.arange(4.0) * 0.5, version=(3, 0))


if __name__ == "__main__":
    main()
