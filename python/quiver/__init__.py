"""Quiver: real-time deformable objects by model reduction (reduced St.Venant-Kirchhoff).

Python bindings of the runtime's C API (quiver/quiver.h), plus helpers to bake a model with the
``quiver-bake`` executable and to read the bake's HDF5 archive::

    import quiver

    model = quiver.Model("beam.qvr")
    beam = quiver.Instance(model)
    beam.set_gravity((0, 0, -quiver.STANDARD_GRAVITY))
    beam.step(60)                      # one second at the model's 1/60 s
    x = beam.positions()               # (n, 3) float32

The model's stored arrays (``rest_positions``, ``triangles``, ...) are read-only NumPy views of its
memory; an instance keeps its model alive, and a view keeps its model alive.
"""
import os
import shutil
import subprocess
from pathlib import Path

from . import _quiver
from ._quiver import (CONTACT_DTYPE, ELASTICITIES, INTEGRATORS, SOLVERS, STANDARD_GRAVITY, Box, Capsule, Collider,
                      FormatError, Instance, MeshCollider, Model, ModelInfo, Plane, RigidState, Sphere, StepStatus,
                      TriangleMesh, World, step_many)

__version__ = _quiver.__version__

__all__ = ["CONTACT_DTYPE", "ELASTICITIES", "INTEGRATORS", "SOLVERS", "STANDARD_GRAVITY", "BakeError", "Box", "Capsule",
           "Collider", "FormatError", "Instance", "MeshCollider", "Model", "ModelInfo", "Plane", "RigidState", "Sphere",
           "StepStatus", "TriangleMesh", "World", "bake", "read_archive", "step_many"]


class BakeError(RuntimeError):
    """quiver-bake failed: the message ends with its standard error; ``returncode``, ``stdout``,
    ``stderr`` and ``command`` say more."""

    def __init__(self, command, returncode, stdout, stderr):
        self.command, self.returncode, self.stdout, self.stderr = command, returncode, stdout, stderr
        super().__init__(f"quiver-bake failed (exit status {returncode}): {stderr.strip() or stdout.strip()}")


def _find(environment, *names):
    found = os.environ.get(environment)
    for name in names:
        found = found or shutil.which(name)
    return found


def _arguments(options):
    """Keyword arguments as quiver-bake options: fix="x<0.01" is --fix x<0.01, no_fidelity=True is
    --no-fidelity, a list repeats the option, False and None leave it out."""
    args = []
    for key, value in options.items():
        flag = "--" + key.replace("_", "-")
        if value is None or value is False:
            continue
        if value is True:
            args.append(flag)
        elif isinstance(value, (list, tuple)):
            for item in value:
                args += [flag, str(item)]
        else:
            args += [flag, str(value)]
    return args


def bake(mesh, output, ranks=1, *, mpiexec=None, mpiexec_args=(), quiet=True, timeout=None, **options):
    """Bakes `mesh` into OUTPUT.qvr (with OUTPUT.h5 and OUTPUT.xmf beside it) and returns the
    .qvr's path. `output` may end in ".qvr".

    Runs the ``quiver-bake`` executable: $QUIVER_BAKE, else ``quiver-bake`` on the PATH. With
    ranks > 1 it runs under MPI: `mpiexec` (else $MPIEXEC, else mpiexec or mpirun on the PATH)
    with ``-n ranks`` and `mpiexec_args` (e.g. ``("--oversubscribe",)`` for more ranks than cores
    with Open MPI). Every other keyword is a quiver-bake option (``quiver-bake --help``)::

        quiver.bake("beam.vtu", "beam", ranks=2, fix="x<min+1e-9", E=1e6, nu=0.45, density=1000,
                    modes=6, rank=10, no_fidelity=True)

    The bake runs in its own process, not in this one. That is also what lets it choose its BLAS
    kernels: quiver-bake re-executes itself with OPENBLAS_CORETYPE set for the CPU, which a Python
    process that has already loaded NumPy's OpenBLAS could not do for itself.

    Raises BakeError (with quiver-bake's standard error) when the bake fails, FileNotFoundError
    when quiver-bake or mpiexec cannot be found, subprocess.TimeoutExpired after `timeout` s.
    """
    executable = _find("QUIVER_BAKE", "quiver-bake")
    if not executable:
        raise FileNotFoundError("quiver-bake not found: set QUIVER_BAKE or put quiver-bake on the PATH")
    if int(ranks) < 1:
        raise ValueError(f"ranks must be at least 1, got {ranks}")
    output = os.fspath(output)
    if output.endswith(".qvr"):
        output = output[:-len(".qvr")]
    command = [executable, *_arguments(options), *(["--quiet"] if quiet else []), "-o", output, os.fspath(mesh)]
    if ranks > 1:
        launcher = mpiexec or _find("MPIEXEC", "mpiexec", "mpirun")
        if not launcher:
            raise FileNotFoundError("mpiexec not found: pass mpiexec=, set MPIEXEC or install MPI (or bake with ranks=1)")
        command = [launcher, "-n", str(int(ranks)), *mpiexec_args, *command]
    done = subprocess.run(command, capture_output=True, text=True, stdin=subprocess.DEVNULL, timeout=timeout)
    if done.returncode != 0:
        raise BakeError(command, done.returncode, done.stdout, done.stderr)
    return Path(output + ".qvr")


def read_archive(path):
    """Every dataset of a bake archive (NAME.h5, formats/ARCHIVE.md) as NumPy arrays, keyed by
    its path: "/mesh/vertices" (n, 3), "/mesh/tets" (m, 4), "/mesh/file_vertex" (n,),
    "/modes/eigenvalues" (k,), "/modes/frequencies_hz" (k,), "/modes/vectors" (k, n, 3),
    "/derivatives/vectors" (P, n, 3), "/basis/vectors" (r, n, 3), "/polynomials/energy_coefficients",
    "/fidelity/...", ... A vector field (c, n, 3) is entry [j, v, :] = vector j's displacement at
    vertex v; as a 3n x c matrix, ``a.reshape(c, -1).T``. Vertex v is row v of /mesh/vertices,
    the same order as a Model made by the same bake (Model.vertex_map and /mesh/file_vertex both
    map to the mesh file).

    Attributes (strings and numbers) are not included: read them with h5py, e.g.
    ``h5py.File(path)["/provenance"].attrs["command_line"]``. Needs h5py (Debian: python3-h5py).
    Raises ValueError for a file that is not a bake archive of schema version 1.
    """
    import h5py

    arrays = {}
    with h5py.File(path, "r") as f:
        if f.attrs.get("format") != "quiver bake archive" or f.attrs.get("schema_version") != 1:
            raise ValueError(f"{os.fspath(path)}: not a quiver bake archive of schema version 1")

        def keep(name, item):
            if isinstance(item, h5py.Dataset):
                arrays["/" + name] = item[()]

        f.visititems(keep)
    return arrays
