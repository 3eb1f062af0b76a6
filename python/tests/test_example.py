"""examples/python_quickstart.py runs, accepts d'Eon (exit-blur switches) and plots."""
import os
import subprocess
import sys


def test_python_quickstart_example(source_dir, tmp_path):
    script = os.path.join(source_dir, "examples", "python_quickstart.py")
    out = subprocess.run([sys.executable, script, str(tmp_path)], capture_output=True, text=True,
                         timeout=240, env=dict(os.environ, OMP_NUM_THREADS="2"))
    assert out.returncode == 0, out.stderr
    assert "judged lobes accepted" in out.stdout
    png = tmp_path / "quickstart_marginals.png"
    assert png.exists() and png.stat().st_size > 20_000
    with open(png, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"
