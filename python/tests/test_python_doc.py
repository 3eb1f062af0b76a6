"""docs/PYTHON.md's python blocks run, in order, in one namespace (in an empty
folder): every example of the user guide works as shown."""
import os
import re

import pytest


def test_every_python_block_of_the_guide_runs(source_dir, tmp_path, monkeypatch):
    pytest.importorskip("pandas")
    pytest.importorskip("xarray")
    with open(os.path.join(source_dir, "docs", "PYTHON.md")) as f:
        blocks = re.findall(r"^```python\n(.*?)^```", f.read(), re.S | re.M)
    assert len(blocks) >= 8
    monkeypatch.chdir(tmp_path)
    namespace = {}
    for i, block in enumerate(blocks):
        try:
            exec(compile(block, "docs/PYTHON.md block %d" % (i + 1), "exec"), namespace)
        except Exception as e:
            pytest.fail("docs/PYTHON.md python block %d fails: %r\n%s" % (i + 1, e, block))
    # What the guide says the blocks show.
    assert namespace["comparison"].accepted
    assert not namespace["fiberlab"].compare(namespace["result"], namespace["mine"]).accepted
    fit = namespace["fit"]
    assert fit.converged and abs(fit.values["beta_long"] - 6) <= 5 * fit.errors["beta_long"] + 1e-3
