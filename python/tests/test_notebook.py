"""examples/fiber_study.ipynb runs from top to bottom in a Jupyter kernel
(Debian's python3-nbclient and python3-ipykernel), and says what it should:
both models judged, the fit converged near the configured width."""
import os
import re

import pytest


def test_study_notebook_runs(source_dir, tmp_path):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    pytest.importorskip("ipykernel")
    pytest.importorskip("xarray")
    nb = nbformat.read(os.path.join(source_dir, "examples", "fiber_study.ipynb"), as_version=4)
    os.environ.pop("MPLBACKEND", None)  # the kernel's inline backend shows the figure
    os.environ.setdefault("OMP_NUM_THREADS", "2")
    os.environ.setdefault("PYDEVD_DISABLE_FILE_VALIDATION", "1")  # ipykernel's debugger notice
    nbclient.NotebookClient(nb, timeout=120, kernel_name="python3",
                            resources={"metadata": {"path": str(tmp_path)}}).execute()
    text = "\n".join(o.get("text", "") for cell in nb.cells if cell.cell_type == "code"
                     for o in cell.get("outputs", []) if o.get("output_type") == "stream")
    assert text.count("judged lobes accepted") == 2
    m = re.search(r"beta_long = (\S+) \+- (\S+) deg", text)
    assert m, text
    value, error = float(m.group(1)), float(m.group(2))
    assert abs(value - 6.0) <= 5 * error + 1e-3
    images = [o for cell in nb.cells if cell.cell_type == "code" for o in cell.get("outputs", [])
              if "image/png" in o.get("data", {})]
    assert len(images) == 1
    assert list(tmp_path.iterdir()) == []  # the study writes nothing
