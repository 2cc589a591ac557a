#!/usr/bin/python3
"""`cpack -G DEB` makes a package that Debian 12 can install: its dependencies resolve against the
system's package lists (apt-get's own simulation), and what it holds works from where it lands:
the tools bake and run a model on 2 ranks, and a CMake project builds against its package files.
The package is unpacked into a scratch root (dpkg-deb -x) rather than installed, so that the test
never changes the machine it runs on (fresh_debian_test.py installs it into a fresh Debian 12)."""
import glob
import os
import subprocess
import tempfile
import unittest

BUILD = os.environ["QUIVER_BUILD"]
SOURCE = os.environ["QUIVER_SOURCE"]
VERSION = os.environ["QUIVER_VERSION"]
MPIEXEC = os.environ.get("MPIEXEC") or "mpirun"


def run(*args, **kwargs):
    p = subprocess.run(list(map(str, args)), capture_output=True, text=True, stdin=subprocess.DEVNULL, **kwargs)
    if p.returncode != 0:
        raise AssertionError(f"failed: {' '.join(map(str, args))}\n{p.stdout}\n{p.stderr}")
    return p.stdout


def make_deb(folder):
    run("cpack", "-G", "DEB", "--config", os.path.join(BUILD, "CPackConfig.cmake"), "-B", folder)
    debs = glob.glob(os.path.join(folder, "*.deb"))
    assert len(debs) == 1, debs
    return debs[0]


class DebianPackage(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.deb = make_deb(cls.tmp.name)
        cls.root = os.path.join(cls.tmp.name, "root")
        run("dpkg-deb", "-x", cls.deb, cls.root)
        cls.usr = os.path.join(cls.root, "usr")

    def test_control_fields(self):
        self.assertEqual(run("dpkg-deb", "-f", self.deb, "Package").strip(), "quiver")
        self.assertEqual(run("dpkg-deb", "-f", self.deb, "Version").strip(), VERSION)
        depends = run("dpkg-deb", "-f", self.deb, "Depends")
        for package in ("libpetsc-real3.18", "libslepc-real3.18", "libhdf5-openmpi-103-1", "openmpi-bin", "libstdc++6"):
            self.assertIn(package, depends)

    def test_contents(self):
        files = {line.split()[5].lstrip(".") for line in run("dpkg-deb", "-c", self.deb).splitlines()}
        for path in ("/usr/bin/quiver", "/usr/bin/quiver-bake", "/usr/bin/quiver-mesh", "/usr/bin/quiver-view",
                     "/usr/include/quiver/quiver.h", "/usr/lib/libquiver_runtime.so." + ".".join(VERSION.split(".")[:2]), "/usr/lib/libquiver_runtime.a",
                     "/usr/lib/cmake/Quiver/QuiverConfig.cmake", "/usr/lib/pkgconfig/quiver.pc",
                     "/usr/share/doc/quiver/copyright", "/usr/lib/python3/dist-packages/quiver/__init__.py"):
            self.assertIn(path, files)

    def test_apt_resolves_its_dependencies(self):
        out = run("apt-get", "install", "-s", "--no-install-recommends", self.deb)
        self.assertIn("Inst quiver (" + VERSION, out)

    def test_the_packaged_tools_bake_and_a_project_builds_against_the_package(self):
        bin_dir = os.path.join(self.usr, "bin")
        work = os.path.join(self.tmp.name, "work")
        os.makedirs(work)
        mesh, model = os.path.join(work, "beam.vtu"), os.path.join(work, "beam")
        run(os.path.join(bin_dir, "quiver-mesh"), "beam", "--size", "1,0.1,0.1", "--cells", "8,2,2", "-o", mesh)
        run(MPIEXEC, "-n", 2, "--oversubscribe", os.path.join(bin_dir, "quiver-bake"), mesh, "--fix", "x<min+1e-9",
            "--modes", 6, "--rank", 10, "--no-fidelity", "--quiet", "-o", model)
        self.assertIn('"r": 10', run(os.path.join(bin_dir, "quiver"), "info", model + ".qvr"))
        build = os.path.join(work, "consumer")
        run("cmake", "-S", os.path.join(SOURCE, "tests", "install", "consumer"), "-B", build, "-G", "Ninja",
            "-DCMAKE_PREFIX_PATH=" + self.usr, "-DQUIVER_EXAMPLE=" + os.path.join(SOURCE, "examples", "embed", "main.c"))
        run("cmake", "--build", build)
        self.assertIn("from C++: r = 10", run(os.path.join(build, "consumer_cpp"), model + ".qvr"))


if __name__ == "__main__":
    unittest.main(verbosity=2)
