#!/usr/bin/python3
"""What the built programs load, against the licences the project allows (issue #16): the runtime
needs the C and C++ standard libraries only and exports its C API only; every library a tool links
directly is one audited here, none GPL. A new dependency fails this test until it is audited and
listed in README.md's Licences."""
import os
import subprocess
import unittest

# soname -> licence, audited from each Debian package's copyright file. The system libraries are
# LGPL (glibc) or GPL with the GCC Runtime Library Exception, which allows any program to use them.
AUDITED = {
    "libc.so.6": "LGPL-2.1+ (glibc)",
    "libm.so.6": "LGPL-2.1+ (glibc)",
    "libstdc++.so.6": "GPL-3+ with the GCC Runtime Library Exception",
    "libgcc_s.so.1": "GPL-3+ with the GCC Runtime Library Exception",
    "libpetsc_real.so.3.18": "BSD-2-Clause (PETSc)",
    "libslepc_real.so.3.18": "BSD-2-Clause (SLEPc)",
    "libmpi.so.40": "BSD-3-Clause (Open MPI)",
    "libmpi_cxx.so.40": "BSD-3-Clause (Open MPI)",
    "libhdf5_openmpi.so.103": "BSD-3-Clause (HDF5)",
    "libmetis.so.5": "Apache-2.0 (METIS)",
    "libopenblas.so.0": "BSD-3-Clause (OpenBLAS)",
    "libtinyxml2.so.9": "Zlib (TinyXML-2)",
    "libz.so.1": "Zlib",
    "libassimp.so.5": "BSD-3-Clause (Assimp)",
    "libpng16.so.16": "libpng-2.0",
    "libgif.so.7": "MIT (giflib)",
    "libglfw.so.3": "Zlib (GLFW)",
    "libepoxy.so.0": "MIT (libepoxy)",
    "libstb.so.0": "MIT or public domain (stb)",
}
STANDARD = {"libc.so.6", "libm.so.6", "libstdc++.so.6", "libgcc_s.so.1"}
# Debian 12's PETSc is itself linked with these (the bake never calls them): README.md says so.
GPL_THROUGH_PETSC = ("libfftw3", "libumfpack", "libspqr", "libcholmod")


def needed(path):
    out = subprocess.run(["readelf", "-d", path], capture_output=True, text=True, check=True).stdout
    return {line.split("[")[1].rstrip("]") for line in out.splitlines() if "(NEEDED)" in line}


def loaded(path):
    out = subprocess.run(["ldd", path], capture_output=True, text=True, check=True).stdout
    return {line.split()[0] for line in out.splitlines() if "=>" in line}


class Licences(unittest.TestCase):
    def test_the_runtime_needs_the_standard_libraries_only_and_exports_its_c_api_only(self):
        runtime = os.environ["QUIVER_RUNTIME_SHARED"]
        self.assertLessEqual(needed(runtime), STANDARD)
        out = subprocess.run(["nm", "-D", "--defined-only", runtime], capture_output=True, text=True, check=True).stdout
        exported = [line.split()[-1] for line in out.splitlines()]
        self.assertGreater(len(exported), 50)
        self.assertEqual([name for name in exported if not name.startswith("qv_")], [])

    def test_every_library_a_tool_links_is_audited(self):
        for tool in os.environ["QUIVER_TOOLS"].split(","):
            with self.subTest(tool=os.path.basename(tool)):
                unaudited = needed(tool) - AUDITED.keys()
                self.assertEqual(unaudited, set(), "not audited: add it to AUDITED and README.md's Licences")
                self.assertFalse([name for name in needed(tool) if "GPL" in AUDITED[name] and name not in STANDARD])

    def test_the_gpl_libraries_in_the_bake_come_through_petsc_only(self):
        bake = next(t for t in os.environ["QUIVER_TOOLS"].split(",") if t.endswith("quiver-bake"))
        through = [name for name in loaded(bake) if name.startswith(GPL_THROUGH_PETSC)]
        petsc = next(name for name in needed(bake) if name.startswith("libpetsc"))
        petsc_path = next(line.split("=>")[1].split()[0] for line in
                          subprocess.run(["ldd", bake], capture_output=True, text=True).stdout.splitlines()
                          if line.strip().startswith(petsc))
        self.assertLessEqual(set(through), loaded(petsc_path))
        self.assertFalse(set(through) & needed(bake))
        print("loaded by Debian's PETSc, never called by the bake:", ", ".join(sorted(through)) or "none")


if __name__ == "__main__":
    unittest.main(verbosity=2)
