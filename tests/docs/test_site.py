"""The docs site builds in strict mode, its generated reference covers every registered kind and preset, and a
reader's browser shows the figures of the home page, a getting-started page and a reproduction page."""

from __future__ import annotations

import html
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from browser import Browser, find_chromium

from cerebx import registry
from cerebx.guard import conf_roots

pytestmark = pytest.mark.integration

ROOT = Path(__file__).resolve().parents[2]
MKDOCS = Path(sys.executable).with_name("mkdocs")
LOOKED_AT = ("index.html", "getting-started/first-report/index.html", "reproductions/thesis-ch3/index.html")


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    if not MKDOCS.exists():
        pytest.skip("the docs tools are not installed (pip install -e '.[docs]', or make docs)")
    out = tmp_path_factory.mktemp("site")
    done = subprocess.run([str(MKDOCS), "build", "--strict", "--site-dir", str(out)], cwd=ROOT, capture_output=True,
                          text=True, timeout=900, env={**os.environ, "DISABLE_MKDOCS_2_WARNING": "true"})
    assert done.returncode == 0, done.stderr[-4000:]
    assert not [ln for ln in done.stderr.splitlines() if ln.startswith("WARNING")], done.stderr[-4000:]
    return out


def test_the_options_reference_names_every_kind_and_preset(site):
    page = html.unescape((site / "reference" / "options" / "index.html").read_text())
    registry.load_plugins()
    missing = [f"{group}: {kind}" for group, reg in registry.GROUPS.items() for kind in reg.kinds()
               if f'id="{group}-{kind}"' not in page]
    assert missing == []
    presets = {(f.parent.name, f.stem) for root in conf_roots() for f in root.rglob("*.yaml")
               if f.parent != root and f.parent.name != "launcher"}
    assert presets and [p for p in presets if f"<code>{p[1]}</code>" not in page] == []


@pytest.mark.skipif(find_chromium() is None, reason="no chromium on this machine (apt-get install chromium)")
def test_a_reader_sees_the_figures(site, tmp_path):
    with Browser() as browser:
        for rel in LOOKED_AT:
            shot = tmp_path / (re.sub(r"\W+", "_", rel) + ".png")
            seen = browser.look((site / rel).as_uri(), shot)
            assert seen["loaded"], f"{rel}: no figure shown"
            assert seen["broken"] == [], f"{rel}: broken images {seen['broken']}"
            assert shot.stat().st_size > 10_000
