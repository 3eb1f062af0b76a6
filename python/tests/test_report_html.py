"""`fiberlab compare --report DIR` and `fiberlab energy --report DIR` write a
self-contained DIR/report.html naming every incident direction, which
headless Chromium renders (where it is installed)."""
import os
import re
import shutil
import struct
import subprocess
import tempfile

import pytest


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n", path
    return struct.unpack(">II", head[16:24])


def assert_self_contained(page, folder):
    # Every image inline; no script, no stylesheet or URL to fetch. The only
    # links: anchors in the page and the SVG files beside it.
    assert "<script" not in page
    assert not re.search(r'src\s*=\s*"(?!data:)', page)
    for target in re.findall(r'href\s*=\s*"([^"]*)"', page):
        if not target.startswith("#"):
            assert re.fullmatch(r"[A-Za-z0-9_.]+\.svg", target), target
            assert (folder / target).exists(), target
    assert "http://" not in page and "https://" not in page
    assert "url(" not in page


def assert_svg_beside_every_png(folder, page):
    pngs = sorted(p.stem for p in folder.glob("*.png"))
    assert pngs and pngs == sorted(p.stem for p in folder.glob("*.svg"))
    for stem in pngs:
        assert 'href="%s.svg"' % stem in page, stem


def shown_width(page, alt_part):
    """The width attribute of the <img> whose alt text contains alt_part,
    and the pixel width of its embedded PNG."""
    import base64
    m = re.search(r'<img alt="[^"]*%s[^"]*" width="(\d+)" height="(\d+)" src="data:image/png;base64,([^"]+)"'
                  % re.escape(alt_part), page)
    assert m, alt_part
    head = base64.b64decode(m.group(3)[:64])
    return int(m.group(1)), struct.unpack(">I", head[16:20])[0]


def render_in_chromium(page_path, shot):
    """Headless Chromium screenshot of the page; None when Chromium is missing."""
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    if not browser:
        return None
    with tempfile.TemporaryDirectory() as profile:
        out = subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                              "--no-first-run", "--disable-background-networking", "--disable-component-update",
                              "--disable-sync", "--user-data-dir=" + profile, "--window-size=1280,2400",
                              "--screenshot=" + str(shot), "file://" + str(page_path)],
                             capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert "CONSOLE" not in out.stderr and "Uncaught" not in out.stderr, out.stderr[-2000:]
    return shot


@pytest.fixture(scope="module")
def compare_report(smooth_result, fiberlab_binary, tmp_path_factory):
    d = tmp_path_factory.mktemp("report")
    result = d / "smooth.h5"
    smooth_result.save(result)
    env = dict(os.environ, FIBERLAB_REPORT_MAX_FIGURES="1")  # direction k=1 is left out of the figures
    out = subprocess.run([fiberlab_binary, "compare", str(result), "--model", "exact", "--set", "absorption=chord",
                          "--report", str(d / "rep")], capture_output=True, text=True, timeout=300, env=env)
    assert out.returncode in (0, 1), out.stderr
    return d / "rep", out.stdout


def test_compare_report_html_is_self_contained_and_names_every_direction(compare_report):
    rep, stdout = compare_report
    page_path = rep / "report.html"
    assert page_path.exists(), stdout
    assert "report.html" in stdout
    page = page_path.read_text()
    assert_self_contained(page, rep)
    assert_svg_beside_every_png(rep, page)
    for name in ("theta_i = 0.00 deg, phi_i = 0.00 deg", "theta_i = 40.00 deg, phi_i = 0.00 deg"):
        assert page.count(name) >= 2, name  # in the list and as a section heading
    assert "Left out of the figures" in page and "first 1 incident directions" in page
    assert page.count("data:image/png;base64,") == 1 + 3  # energy + the three figures of k = 0
    assert "sr<sup>-1</sup>" in page
    assert "[report.html](report.html)" in (rep / "report.md").read_text()


def test_compare_report_figure_sizes(compare_report):
    rep, _ = compare_report
    lobes = 4  # (plot_report.py's docstring: heights per lobe)
    for name, size in (("compare_theta0.0_phi0.0_heatmaps.png", (1200, 150 + 550 * lobes)),
                       ("compare_theta0.0_phi0.0_marginals.png", (1200, 125 + 350 * lobes)),
                       ("compare_theta0.0_phi0.0_polar.png", (1200, 450)), ("compare_energy.png", (1200, 425))):
        assert png_size(rep / name) == size, name
        assert (rep / name).stat().st_size > 20_000, name
    assert not (rep / "compare_theta40.0_phi0.0_heatmaps.png").exists()  # left out


def test_compare_report_shows_heatmaps_at_natural_size(compare_report):
    # Each heatmap panel is >= 400 px wide in the 1200 px PNG
    # (test_plot_helpers.py); the page shows the PNG unscaled: its width
    # attribute is the PNG's own and no style shrinks it (a narrow window
    # scrolls the figure instead).
    rep, _ = compare_report
    page = (rep / "report.html").read_text()
    shown, png = shown_width(page, "heatmaps")
    assert shown == png == 1200
    style = page[page.index("<style>"):page.index("</style>")]
    assert re.search(r"\.fig img \{[^}]*max-width: none", style)
    assert not re.search(r"(^|[^.\w])img \{[^}]*max-width: *\d", style)


def test_compare_report_renders_in_headless_chromium(compare_report, tmp_path):
    rep, _ = compare_report
    shot = render_in_chromium(rep / "report.html", tmp_path / "shot.png")
    if shot is None:
        pytest.skip("chromium not installed (PNG sizes are checked by the test above)")
    assert png_size(shot) == (1280, 2400)
    import matplotlib.image
    pixels = matplotlib.image.imread(str(shot))
    assert pixels.std() > 0.05  # the page drew text and figures, not a blank sheet


def test_energy_report_html(smooth_result, fiberlab_binary, tmp_path):
    result = tmp_path / "smooth.h5"
    smooth_result.save(result)
    out = subprocess.run([fiberlab_binary, "energy", str(result), "--models", "exact", "--grid-theta", "45",
                          "--grid-phi", "36", "--report", str(tmp_path / "e")], capture_output=True, text=True,
                         timeout=300)
    assert out.returncode == 0, out.stderr
    page = (tmp_path / "e" / "report.html").read_text()
    assert_self_contained(page, tmp_path / "e")
    assert_svg_beside_every_png(tmp_path / "e", page)
    assert page.count("data:image/png;base64,") == 1
    assert "simulation" in page and "exact" in page


def test_energy_report_of_a_white_fiber_has_the_furnace_plot(fiberlab_binary, tmp_path):
    import fiberlab
    white = fiberlab.run({"fiber": {"eta": 1.55, "sigma_a": 0}, "roughness": {"model": "smooth"},
                          "source": {"theta_i": [0, 30, 60]}, "tally": {"n_theta": 45, "n_phi": 36}},
                         photons=20_000, seed=3, progress=False)
    result = tmp_path / "white.h5"
    white.save(result)
    out = subprocess.run([fiberlab_binary, "energy", str(result), "--models", "exact", "--grid-theta", "45",
                          "--grid-phi", "36", "--report", str(tmp_path / "e")], capture_output=True, text=True,
                         timeout=300)
    assert out.returncode == 0, out.stderr
    assert png_size(tmp_path / "e" / "energy_furnace.png") == (1200, 400)
    page = (tmp_path / "e" / "report.html").read_text()
    assert page.count("data:image/png;base64,") == 2 and "White furnace" in page
    assert_self_contained(page, tmp_path / "e")
    assert_svg_beside_every_png(tmp_path / "e", page)
