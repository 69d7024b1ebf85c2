"""A Jupyter server extension, enabled when msdlab is installed: the kernels' websockets
send each message at once (TCP no-delay), and the course's notebooks are saved as the
course keeps them.

The live view sends a small message per state, 60 a second. By default the server's
websocket (tornado) holds a small message until the browser has acknowledged the one
before (Nagle's algorithm), and the browser delays that acknowledgement, so the states
arrive in pairs and unevenly. The extension swaps the kernel websocket connection for
`NoDelayConnection` unless the server's configuration names one
(``--ServerApp.kernel_websocket_connection_class``).

A course notebook marked to be kept without outputs (`msdlab.course.notebook_file`) is
saved without them under its own name (`save_as_kept`), so running one in a checkout of
the course leaves git's copy unchanged; a copy saved under another name keeps its outputs.
Every course notebook, the students' too, is saved with its language described as it
ships (no Python version that the kernel adds), so a save changes only what the user did.

The package installs ``msdlab/jupyter-config/msdlab.json`` as
``<sys.prefix>/etc/jupyter/jupyter_server_config.d/msdlab.json`` (editable installs
too), which enables the extension in every Jupyter server of the environment
(``jupyter lab``, ``jupyter notebook``). The module imports nothing of the engine.
"""

from __future__ import annotations

import asyncio
from pathlib import PurePosixPath
from typing import Any

from jupyter_server.services.kernels.connection.channels import ZMQChannelsWebsocketConnection

from .course.notebook_file import as_kept, is_marked, language_as_shipped, marked_name, unmarked

SETTING = "kernel_websocket_connection_class"


class NoDelayConnection(ZMQChannelsWebsocketConnection):
    """The default kernel websocket connection, with no-delay set on its socket."""

    def connect(self) -> asyncio.Future[None] | None:
        """Set no-delay on the open websocket, then connect it to the kernel."""
        self.websocket_handler.set_nodelay(True)
        return super().connect()


def _jupyter_server_extension_points() -> list[dict[str, str]]:
    """The extension's entry point, as Jupyter server looks it up."""
    return [{"module": "msdlab.jupyter_extension"}]


def save_as_kept(model: dict[str, Any], path: str = "", **_: Any) -> None:
    """Jupyter's pre-save hook: a course notebook saved as the file it is marked to be kept
    as is written without its outputs; saved as another file (``path``, from the server's
    root), it loses the mark and keeps them. A course notebook's language is described as
    it ships."""
    notebook = model.get("content") or {}
    if model.get("type") != "notebook" or not is_marked(notebook):
        return
    language_as_shipped(notebook)
    name = marked_name(notebook)
    if name is None:
        return
    if name == PurePosixPath(path).name:
        as_kept(notebook, name)
    else:
        unmarked(notebook)


def _load_jupyter_server_extension(server: Any) -> None:
    """Save course notebooks as kept (`save_as_kept`); use `NoDelayConnection` for the
    kernels' websockets, unless the configuration names a class."""
    server.contents_manager.register_pre_save_hook(save_as_kept)
    if SETTING in server.config.get("ServerApp", {}):
        return
    server.web_app.settings[SETTING] = NoDelayConnection
    server.log.info("msdlab: kernel websockets send each message at once (TCP no-delay)")
