#!/usr/bin/python3
"""`cpack -G DEB`'s package installs with apt on a fresh, minimal Debian 12 (made by mmdebstrap
from Debian's archive, then thrown away): there it bakes on 2 ranks with the packaged tools, a C
and a C++ project build against its CMake and pkg-config files, and Python imports its module.
Exits 77 (ctest: skipped) without root or mmdebstrap."""
import os
import shutil
import subprocess
import sys
import tempfile

from deb_test import SOURCE, VERSION, make_deb

# Inside the fresh system: install the package with apt, bake on 2 ranks with the packaged tools,
# then build against the packaged CMake and pkg-config files and run what was built.
SCRIPT = """set -e
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
"""

if shutil.which("mmdebstrap") is None or os.geteuid() != 0:
    print("SKIPPED: needs root and mmdebstrap (Debian package) to make a fresh Debian 12")
    sys.exit(77)
with tempfile.TemporaryDirectory() as tmp:
    deb = make_deb(tmp)
    script = os.path.join(tmp, "fresh.sh")
    with open(script, "w") as f:
        f.write(SCRIPT)
    p = subprocess.run(["mmdebstrap", "--variant=apt", "--include=cmake,make,g++,pkg-config",
                        f"--customize-hook=upload {deb} /tmp/quiver.deb",
                        f"--customize-hook=copy-in {os.path.join(SOURCE, 'tests', 'install', 'consumer')} /tmp",
                        f"--customize-hook=upload {os.path.join(SOURCE, 'examples', 'embed', 'main.c')} /tmp/embed.c",
                        f"--customize-hook=upload {script} /tmp/fresh.sh",
                        '--customize-hook=chroot "$1" sh /tmp/fresh.sh',
                        "bookworm", "/dev/null"],
                       capture_output=True, text=True, timeout=1200, stdin=subprocess.DEVNULL)
out = p.stdout + p.stderr
if p.returncode != 0:
    sys.exit(f"the fresh Debian 12 failed:\n{out[-6000:]}")
expected = ["from C++: r = 10", f"python: {VERSION} 10"]
if any(line not in out for line in expected) or out.count("after 30 frames") != 2:
    sys.exit(f"the fresh Debian 12 did not print {expected} and 'after 30 frames' twice:\n{out[-6000:]}")
print("installed with apt on a fresh Debian 12: baked on 2 ranks; C, C++ (CMake), C (pkg-config) and Python ran")
