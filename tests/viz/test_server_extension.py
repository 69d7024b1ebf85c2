"""msdlab's Jupyter server extension: installed with msdlab, it gives the
kernels' websockets TCP no-delay unless the server's configuration names a connection."""

import json
import logging
from pathlib import Path
from types import SimpleNamespace

from jupyter_server.services.kernels.connection.channels import ZMQChannelsWebsocketConnection

from msdlab import jupyter_extension
from msdlab.jupyter_extension import SETTING, NoDelayConnection

ROOT = Path(__file__).resolve().parents[2]


def server(config: dict) -> SimpleNamespace:
    """A Jupyter server as an extension sees it, with the default kernel websocket."""
    settings = {SETTING: ZMQChannelsWebsocketConnection}
    return SimpleNamespace(
        config=config, web_app=SimpleNamespace(settings=settings), log=logging.getLogger()
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
    config = "msdlab/jupyter-config/msdlab.json"
    data_files = f'"etc/jupyter/jupyter_server_config.d" = ["{config}"]'
    assert data_files in (ROOT / "pyproject.toml").read_text()  # into <sys.prefix>/etc/jupyter
    enabled = json.loads((ROOT / config).read_text())["ServerApp"]["jpserver_extensions"]
    assert enabled == {"msdlab.jupyter_extension": True}
    points = jupyter_extension._jupyter_server_extension_points()
    assert points == [{"module": "msdlab.jupyter_extension"}]
