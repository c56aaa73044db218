"""The example notebook runs headless and shows pictures."""

import nbformat
from nbclient import NotebookClient

from conftest import REPO


def test_example_notebook_executes_and_draws(tmp_path):
    nb = nbformat.read(REPO / "python" / "examples" / "water.ipynb", as_version=4)
    NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}).execute()
    images = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs if "image/png" in o.get("data", {})]
    assert len(images) >= 2, [o.get("data", {}).keys() for c in nb.cells for o in c.get("outputs", [])]
    errors = [o for c in nb.cells for o in c.get("outputs", []) if o.get("output_type") == "error"]
    assert not errors, errors
