#!/usr/bin/python3
"""`cpack -G DEB` makes a package that Debian 12 can install: its dependencies resolve against the
system's package lists (apt-get's own simulation), and what it holds works from where it lands:
the tools bake and run a model on 2 ranks, and a CMake project builds against its package files.
The package is unpacked into a scratch root (dpkg-deb -x) rather than installed, so that the test
never changes the machine it runs on; and it is installed with apt into a fresh, minimal Debian 12
made by mmdebstrap from Debian's archive, where a C and a C++ project build against it."""
import glob
import os
import shutil
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


class DebianPackage(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        run("cpack", "-G", "DEB", "--config", os.path.join(BUILD, "CPackConfig.cmake"), "-B", cls.tmp.name)
        debs = glob.glob(os.path.join(cls.tmp.name, "*.deb"))
        assert len(debs) == 1, debs
        cls.deb = debs[0]
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
                     "/usr/include/quiver/quiver.h", "/usr/lib/libquiver_runtime.so.0.6", "/usr/lib/libquiver_runtime.a",
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

    def test_installs_on_a_fresh_debian_12(self):
        if shutil.which("mmdebstrap") is None or os.geteuid() != 0:
            self.skipTest("SKIPPED: needs root and mmdebstrap (Debian package) to make a fresh Debian 12")
        consumer = os.path.join(SOURCE, "tests", "install", "consumer")
        embed = os.path.join(SOURCE, "examples", "embed", "main.c")
        # Inside the fresh system: install the package with apt, bake on 2 ranks with the packaged
        # tools, then build against the packaged CMake and pkg-config files and run what was built.
        script = os.path.join(self.tmp.name, "fresh.sh")
        with open(script, "w") as f:
            f.write("""set -e
cd /tmp
DEBIAN_FRONTEND=noninteractive apt-get install -y -q /tmp/quiver.deb > apt.log 2>&1 || { tail -30 apt.log; exit 1; }
quiver-mesh beam --size 1,0.1,0.1 --cells 8,2,2 -o beam.vtu
OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun -n 2 --oversubscribe \\
  quiver-bake beam.vtu --fix 'x<min+1e-9' --modes 6 --rank 10 --no-fidelity --quiet -o beam
quiver info beam.qvr > info.json
cmake -S /tmp/consumer -B build -DQUIVER_EXAMPLE=/tmp/embed.c > cmake.log 2>&1 || { cat cmake.log; exit 1; }
cmake --build build > build.log 2>&1 || { cat build.log; exit 1; }
build/consumer_cpp beam.qvr
build/consumer_c beam.qvr 30
cc -std=c99 /tmp/embed.c $(pkg-config --cflags --libs quiver) -o embed_pc
./embed_pc beam.qvr 30
python3 -c "import quiver; print('python:', quiver.__version__, quiver.Model('beam.qvr').info.r)"
""")
        p = subprocess.run(["mmdebstrap", "--variant=apt", "--include=cmake,make,g++,pkg-config",
                            f"--customize-hook=upload {self.deb} /tmp/quiver.deb",
                            f"--customize-hook=copy-in {consumer} /tmp",
                            f"--customize-hook=upload {embed} /tmp/embed.c",
                            f"--customize-hook=upload {script} /tmp/fresh.sh",
                            '--customize-hook=chroot "$1" sh /tmp/fresh.sh',
                            "bookworm", "/dev/null"],
                           capture_output=True, text=True, timeout=1200, stdin=subprocess.DEVNULL)
        self.assertEqual(p.returncode, 0, p.stdout[-3000:] + p.stderr[-3000:])
        self.assertIn("from C++: r = 10", p.stdout + p.stderr)
        self.assertEqual((p.stdout + p.stderr).count("after 30 frames"), 2)
        self.assertIn(f"python: {VERSION} 10", p.stdout + p.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
