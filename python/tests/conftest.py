import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def root() -> Path:
    """The repository."""
    return ROOT


@pytest.fixture
def hiperface_bin() -> Path:
    """The `hiperface` command (HIPERFACE_BIN, else the release build)."""
    path = Path(os.environ.get("HIPERFACE_BIN", ROOT / "target" / "release" / "hiperface"))
    if not path.exists():
        pytest.fail(f"{path} does not exist: build it (cargo build --release -p hiperface-conformance) or set HIPERFACE_BIN")
    return path
