"""Looks at the notebook viewer where users see it: JupyterLab in headless Chromium. Runs a
notebook that shows `orbcloud.widget` on a fixture, drags across the frame, and writes the page
before and after the drag (the picture in README.md is a crop of the second).

Needs the package and `jupyterlab playwright` in the environment and a Chromium
(`apt-get install chromium`):  python3 scripts/notebook_screenshot.py OUT_DIR
"""

import json
import pathlib
import shutil
import subprocess
import sys
import tempfile
import time

from playwright.sync_api import sync_playwright

REPO = pathlib.Path(__file__).resolve().parents[1]
PORT = 8899


def main(out: pathlib.Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    root = pathlib.Path(tempfile.mkdtemp(prefix="orbcloud-lab-"))
    shutil.copy(REPO / "tests/fixtures/wavefunctions/h2o_ccpvtz.molden", root)
    source = "import orbcloud\nviewer = orbcloud.widget(orbcloud.load('h2o_ccpvtz.molden'), size=(600, 450))\nviewer"
    cell = {"cell_type": "code", "metadata": {}, "execution_count": None, "outputs": [], "id": "c0", "source": source}
    notebook = {"cells": [cell], "metadata": {"kernelspec": {"display_name": "Python 3", "language": "python", "name": "python3"}}, "nbformat": 4, "nbformat_minor": 5}
    (root / "widget.ipynb").write_text(json.dumps(notebook))
    lab = subprocess.Popen(
        [sys.executable, "-m", "jupyter", "lab", "--no-browser", f"--port={PORT}", "--IdentityProvider.token=orbcloud", f"--ServerApp.root_dir={root}", "--allow-root"],
        stdout=open(out / "lab.log", "w"),
        stderr=subprocess.STDOUT,
    )
    try:
        time.sleep(8)
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=shutil.which("chromium") or shutil.which("chromium-browser"), args=["--no-sandbox"])
            page = browser.new_page(viewport={"width": 1100, "height": 900})
            page.goto(f"http://localhost:{PORT}/lab/tree/widget.ipynb?token=orbcloud")
            page.wait_for_selector(".jp-Notebook .jp-Cell", timeout=60000)
            time.sleep(3)
            page.click(".jp-Cell .jp-InputArea-editor")
            page.keyboard.press("Shift+Enter")
            frame = page.wait_for_selector(".jp-OutputArea-output img", timeout=120000)
            time.sleep(6)
            page.screenshot(path=str(out / "widget_before.png"))
            box = frame.bounding_box()
            x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
            page.mouse.move(x, y)
            page.mouse.down()
            for k in range(1, 16):
                page.mouse.move(x + 8 * k, y + 3 * k)
                time.sleep(0.1)
            page.mouse.up()
            time.sleep(4)
            page.screenshot(path=str(out / "widget_after.png"))
            browser.close()
    finally:
        lab.terminate()
        lab.wait()
        shutil.rmtree(root, ignore_errors=True)
    print(f"wrote {out / 'widget_before.png'} and {out / 'widget_after.png'}")


if __name__ == "__main__":
    main(pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "target/notebook-screenshot"))
