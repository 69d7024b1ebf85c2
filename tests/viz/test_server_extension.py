"""msdlab's Jupyter server extension: installed with msdlab, it gives the
kernels' websockets TCP no-delay unless the server's configuration names a connection,
and saves the course's notebooks without outputs."""

import json
import logging
import sys
from importlib import metadata
from pathlib import Path
from types import SimpleNamespace

import pytest
from jupyter_server.services.contents.filemanager import FileContentsManager
from jupyter_server.services.kernels.connection.channels import ZMQChannelsWebsocketConnection

from msdlab import jupyter_extension
from msdlab.course import notebook_file
from msdlab.jupyter_extension import SETTING, NoDelayConnection

ROOT = Path(__file__).resolve().parents[2]
CONFIG = "msdlab/jupyter-config/msdlab.json"
INSTALLED = "etc/jupyter/jupyter_server_config.d/msdlab.json"


def server(config: dict, contents: object = None) -> SimpleNamespace:
    """A Jupyter server as an extension sees it, with the default kernel websocket."""
    settings = {SETTING: ZMQChannelsWebsocketConnection}
    return SimpleNamespace(
        config=config,
        web_app=SimpleNamespace(settings=settings),
        log=logging.getLogger(),
        contents_manager=contents or FileContentsManager(),
    )


def test_the_kernels_websockets_get_no_delay():
    plain = server({})
    jupyter_extension._load_jupyter_server_extension(plain)
    assert plain.web_app.settings[SETTING] is NoDelayConnection


def test_a_connection_the_configuration_names_is_kept():
    configured = server({"ServerApp": {SETTING: "some.Connection"}})
    jupyter_extension._load_jupyter_server_extension(configured)
    assert configured.web_app.settings[SETTING] is ZMQChannelsWebsocketConnection


def test_the_package_installs_the_configuration_that_enables_it():
    pyproject = (ROOT / "pyproject.toml").read_text()
    assert "[tool.hatch.build.targets.wheel.shared-data]" in pyproject  # editable installs too
    assert f'"{CONFIG}" = "{INSTALLED}"' in pyproject  # into <sys.prefix>
    enabled = json.loads((ROOT / CONFIG).read_text())["ServerApp"]["jpserver_extensions"]
    assert enabled == {"msdlab.jupyter_extension": True}
    points = jupyter_extension._jupyter_server_extension_points()
    assert points == [{"module": "msdlab.jupyter_extension"}]


def test_an_editable_install_enables_it_too():
    """This environment's msdlab is the checkout installed with ``pip install -e``."""
    try:
        metadata.distribution("msdlab")
    except metadata.PackageNotFoundError:
        pytest.skip("msdlab is not installed in this environment (run from the source)")
    installed = Path(sys.prefix, INSTALLED)
    assert installed.is_file(), f"{installed} is missing: Jupyter would not load msdlab"
    assert json.loads(installed.read_text()) == json.loads((ROOT / CONFIG).read_text())


def after_a_run(kept: dict, run: dict) -> dict:
    """The notebook ``kept`` as JupyterLab sends it to be saved after running it: the run's
    outputs and execution counts, its own kernel metadata, cell metadata of its own."""
    notebook = json.loads(json.dumps(kept))
    notebook["metadata"]["kernelspec"]["display_name"] = "Python 3 (ipykernel)"
    notebook["metadata"]["language_info"] = {
        "codemirror_mode": {"name": "ipython", "version": 3},
        "name": "python",
        "version": sys.version.split()[0],
    }
    count = 0
    for cell, ran in zip(notebook["cells"], run["cells"], strict=True):
        cell["metadata"] = {"scrolled": True, "execution": {"iopub.status.idle": "2026-11-26"}}
        if cell["cell_type"] == "code":
            count += 1
            cell["execution_count"] = count
            picture = {"output_type": "display_data", "metadata": {}, "data": {"image/png": "iVBO"}}
            cell["outputs"] = [*ran["outputs"], picture]
    return notebook


def save(folder: Path, name: str, content: dict) -> bytes:
    """Save ``content`` as ``name`` in ``folder`` the way the Jupyter server does, with the
    extension loaded; return the bytes written."""
    contents = FileContentsManager(root_dir=str(folder))
    jupyter_extension._load_jupyter_server_extension(server({}, contents))
    contents.save({"type": "notebook", "format": "json", "content": content}, name)
    return (folder / name).read_bytes()


def test_a_course_notebook_run_and_saved_is_left_as_git_keeps_it(tmp_path):
    tracked = (ROOT / "notebooks" / "task2.ipynb").read_bytes()
    run = json.loads((ROOT / "docs" / "notebooks" / "task2.ipynb").read_text())
    (tmp_path / "task2.ipynb").write_bytes(tracked)
    ran = after_a_run(json.loads(tracked), run)
    assert any(cell.get("outputs") for cell in ran["cells"])
    assert save(tmp_path, "task2.ipynb", ran) == tracked


def test_an_edit_of_a_course_notebook_is_saved(tmp_path):
    kept = json.loads((ROOT / "notebooks" / "task2.ipynb").read_text())
    kept["cells"][0]["source"] = "# My notes"
    saved = json.loads(save(tmp_path, "task2.ipynb", kept))
    assert saved["cells"][0]["source"] == ["# My notes"]


def test_a_course_notebook_saved_under_another_name_keeps_its_outputs(tmp_path):
    """Save As: the copy is the user's own notebook, no longer git's, and keeps what it shows;
    saved again, it still does."""
    tracked = json.loads((ROOT / "notebooks" / "task2.ipynb").read_text())
    ran = after_a_run(
        tracked, json.loads((ROOT / "docs" / "notebooks" / "task2.ipynb").read_text())
    )
    outputs = [cell.get("outputs") for cell in ran["cells"]]
    (tmp_path / "mine").mkdir()
    saved = json.loads(save(tmp_path, "mine/task2 with outputs.ipynb", ran))
    assert [cell.get("outputs") for cell in saved["cells"]] == outputs
    assert "msdlab" not in saved["metadata"]
    again = json.loads(save(tmp_path, "mine/task2 with outputs.ipynb", saved))
    assert [cell.get("outputs") for cell in again["cells"]] == outputs


def test_other_notebooks_keep_their_outputs(tmp_path):
    run = json.loads((ROOT / "docs" / "notebooks" / "task2.ipynb").read_text())
    assert "msdlab" not in run["metadata"]
    saved = json.loads(save(tmp_path, "mine.ipynb", run))
    assert [cell.get("outputs") for cell in saved["cells"]] == [
        cell.get("outputs") for cell in run["cells"]
    ]
    assert any(cell.get("outputs") for cell in saved["cells"])


def for_students(kept: dict, name: str) -> dict:
    """The notebook ``kept`` as the student release ships it (`release._write_for_students`)."""
    notebook = json.loads(json.dumps(kept))
    notebook_file.as_kept(notebook, name)
    notebook_file.for_students(notebook, name)
    return notebook


def test_a_students_notebook_run_and_saved_keeps_its_outputs_and_its_metadata(tmp_path):
    """In the release: the run's outputs are saved, the metadata as shipped (the kernel's
    Python version is not written), and saved again nothing changes."""
    shipped = for_students(
        json.loads((ROOT / "notebooks" / "task2.ipynb").read_text()), "task2.ipynb"
    )
    ran = after_a_run(
        shipped, json.loads((ROOT / "docs" / "notebooks" / "task2.ipynb").read_text())
    )
    outputs = [cell.get("outputs") for cell in ran["cells"]]
    saved = save(tmp_path, "task2.ipynb", ran)
    assert json.loads(saved)["metadata"] == shipped["metadata"]
    assert [cell.get("outputs") for cell in json.loads(saved)["cells"]] == outputs
    again = json.loads(saved)
    again["metadata"]["language_info"]["version"] = sys.version.split()[0]  # from the kernel
    assert save(tmp_path, "task2.ipynb", again) == saved


def test_a_notebook_of_another_language_keeps_its_description(tmp_path):
    shipped = for_students(json.loads((ROOT / "notebooks" / "task2.ipynb").read_text()), "x.ipynb")
    shipped["metadata"]["language_info"] = {"name": "R", "version": "4.4.1"}
    saved = json.loads(save(tmp_path, "x.ipynb", shipped))
    assert saved["metadata"]["language_info"] == {"name": "R", "version": "4.4.1"}


def test_the_shipped_metadata_is_what_the_kernel_says_but_its_python_version():
    """The kernel the notebooks name is ipykernel's python3 as this environment has it, and
    its description of the language is the notebooks' but for the version of its Python."""
    kernelspec = pytest.importorskip("jupyter_client.kernelspec")
    from jupyter_client.manager import start_new_kernel

    spec = kernelspec.KernelSpecManager().get_kernel_spec("python3")
    named = notebook_file.METADATA["kernelspec"]
    assert (spec.display_name, spec.language) == (named["display_name"], named["language"])
    manager, client = start_new_kernel(kernel_name="python3")
    try:
        reply = client.kernel_info(reply=True, timeout=60)
    finally:
        client.stop_channels()
        manager.shutdown_kernel(now=True)
    described = reply["content"]["language_info"]
    assert described.pop("version") == ".".join(map(str, sys.version_info[:3]))
    assert described == notebook_file.METADATA["language_info"]
