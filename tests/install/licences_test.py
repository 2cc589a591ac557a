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
    "libdmumps-5.5.so": "CeCILL-C (MUMPS; its PORD ordering public domain)",
    "libmumps_common-5.5.so": "CeCILL-C (MUMPS)",
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
# Everything the binaries load, directly or through the libraries above, by Debian package: all
# permissive or LGPL-like (dynamically linked LGPL libraries leave our code's licence alone), but
# the GPL ones Debian 12's PETSc is itself linked with, which the bake never calls (README.md).
LOADED_PACKAGES = {
    "BSD/MIT/Apache/Zlib/ISC/CeCILL-C/MPL/OpenLDAP/curl/libpng": (
        "libaec0 libamd2 libarpack2 libassimp5 libbrotli1 libbsd0 libcamd2 libccolamd2 libcolamd2 libcombblas1.16.0 "
        "libcurl4 libdraco7 libepoxy0 libevent-core-2.1-7 libevent-pthreads-2.1-7 libffi8 libgif7 libglfw3 "
        "libgssapi-krb5-2 libhdf5-openmpi-103-1 libhwloc15 libhypre-2.26.0 libk5crypto3 libkrb5-3 libkrb5support0 "
        "libldap-2.5-0 libmd0 libmetis5 libminizip1 libmumps-5.5 libnghttp2-14 libopenblas0-pthread libopenmpi3 "
        "libp11-kit0 libparpack2 libpetsc-real3.18 libpng16-16 libpsl5 libptscotch-7.0 libsasl2-2 "
        "libscalapack-openmpi2.2 libscotch-7.0 libslepc-real3.18 libssh2-1 libssl3 libstb0 libsuitesparseconfig5 "
        "libsuperlu-dist8 libsuperlu5 libsz2 libtinyxml2-9 libtrilinos-amesos-13.2 libtrilinos-aztecoo-13.2 "
        "libtrilinos-epetra-13.2 libtrilinos-epetraext-13.2 libtrilinos-galeri-13.2 libtrilinos-ifpack-13.2 "
        "libtrilinos-kokkos-13.2 libtrilinos-ml-13.2 libtrilinos-teuchos-13.2 libtrilinos-trilinosss-13.2 "
        "libtrilinos-triutils-13.2 libtrilinos-zoltan-13.2 libx11-6 libxau6 libxcb1 libxdmcp6 libyaml-0-2 libzstd1 "
        "ocl-icd-libopencl1 zlib1g libbz2-1.0 libcom-err2 liblzma5").split(),
    "LGPL (or LGPL/GPL dual)": ("libc6 libbtf1 libgmp10 libgnutls30 libhogweed6 libidn2-0 libklu1 libnettle8 librtmp1 "
                                "libtasn1-6 libudev1 libunistring2 libquadmath0 libkeyutils1").split(),
    "GPL-3+ with the GCC Runtime Library Exception": "libstdc++6 libgcc-s1 libgfortran5 libgomp1".split(),
    "GPL-2+, through Debian's PETSc only": "libfftw3-double3 libfftw3-mpi3 libumfpack5 libspqr2 libcholmod3".split(),
}
PACKAGE_LICENCE = {package: licence for licence, packages in LOADED_PACKAGES.items() for package in packages}


def needed(path):
    out = subprocess.run(["readelf", "-d", path], capture_output=True, text=True, check=True).stdout
    return {line.split("[")[1].rstrip("]") for line in out.splitlines() if "(NEEDED)" in line}


def loaded(path):
    """soname -> file of every library the binary loads (ldd: directly or not)."""
    out = subprocess.run(["ldd", path], capture_output=True, text=True, check=True).stdout
    return {line.split()[0]: line.split("=>")[1].split()[0] for line in out.splitlines() if "=>" in line}


def packages_of(paths):
    """file -> Debian package of the file it resolves to. dpkg knows some files by their /lib path
    (usrmerge), and a symlink may belong to a -dev package: ask for the real file, both ways."""
    def candidates(path):
        real = os.path.realpath(path)
        return [real, real.replace("/usr/lib/", "/lib/", 1)]
    out = subprocess.run(["dpkg", "-S", *sorted({c for p in paths for c in candidates(p)})],
                         capture_output=True, text=True).stdout
    owner = {}
    for line in out.splitlines():
        package, _, file = line.partition(": ")
        owner[file] = package.split(":")[0]
    return {path: next((owner[c] for c in candidates(path) if c in owner), None) for path in paths}


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

    def test_every_library_loaded_is_audited_and_gpl_ones_come_through_petsc_only(self):
        gpl = set(LOADED_PACKAGES["GPL-2+, through Debian's PETSc only"])
        for binary in os.environ["QUIVER_TOOLS"].split(","):
            libraries = loaded(binary)
            owners = packages_of(libraries.values())
            packages = {name: owners[path] for name, path in libraries.items()}
            with self.subTest(binary=os.path.basename(binary)):
                unaudited = {name: package for name, package in packages.items() if package not in PACKAGE_LICENCE}
                self.assertEqual(unaudited, {}, "not audited: add them to LOADED_PACKAGES and README.md's Licences")
                through_gpl = {name for name, package in packages.items() if package in gpl}
                if through_gpl:
                    petsc = next(path for name, path in libraries.items() if name.startswith("libpetsc"))
                    self.assertLessEqual(through_gpl, set(loaded(petsc)), "a GPL library comes from elsewhere")
                    self.assertFalse(through_gpl & needed(binary))
                    print(os.path.basename(binary), "loads through Debian's PETSc, never calls:", ", ".join(sorted(through_gpl)))

if __name__ == "__main__":
    unittest.main(verbosity=2)
