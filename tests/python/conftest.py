"""Fixtures of the Python module's tests: the suite's two small models (tests/CMakeLists.txt,
fixture test_model), by the paths ctest passes in the environment."""
import os

import numpy as np
import pytest

import quiver


def _environment(name):
    value = os.environ.get(name)
    if not value:
        pytest.fail(f"{name} is not set: run these tests through ctest (ctest -R python.module)")
    return value


@pytest.fixture(scope="session")
def model_path():
    """The fixed beam: 0.6 x 0.1 x 0.1 m, 12 x 2 x 2 cells of six tets, clamped at x = 0, r = 10,
    float64 basis, E = 1 MPa, nu = 0.4, 1000 kg/m^3 (tests/support/small_model.h)."""
    return _environment("QUIVER_MODEL")


@pytest.fixture(scope="session")
def free_model_path():
    """The same beam baked free (no fixed vertex, r = 16): instances can fly."""
    return _environment("QUIVER_FREE_MODEL")


@pytest.fixture(scope="session")
def model(model_path):
    return quiver.Model(model_path)


@pytest.fixture(scope="session")
def free_model(free_model_path):
    return quiver.Model(free_model_path)


@pytest.fixture(scope="session")
def tip(model):
    """The vertex at the free end (x = 0.6) on the section's centre line."""
    X = model.rest_positions
    return int(np.argmin(np.abs(X[:, 0] - 0.6) + np.hypot(X[:, 1] - 0.05, X[:, 2] - 0.05)))


@pytest.fixture(scope="session")
def basis(model):
    """U (3n x r), column j being the displacements of q = e_j (float32 rounding of the stored
    float64 basis)."""
    r = model.info.r
    return np.stack([model.displacements(np.eye(r)[j]).astype(np.float64).reshape(-1) for j in range(r)], axis=1)
