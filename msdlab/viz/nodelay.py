"""Jupyter Server's kernel websocket with TCP no-delay: each message leaves at once.

The live view sends a small message per state, 60 a second. By default the server's
websocket (tornado) waits for the browser's acknowledgement of one small message
before sending the next (Nagle's algorithm), and the browser delays that
acknowledgement, so the states arrive in pairs. Start JupyterLab with

    jupyter lab --ServerApp.kernel_websocket_connection_class=msdlab.viz.nodelay.NoDelayConnection

(or put that setting in ``jupyter_server_config.py``) to send them as they come.
The page shows every state either way; with no-delay they also arrive evenly.
"""

from __future__ import annotations

import asyncio

from jupyter_server.services.kernels.connection.channels import ZMQChannelsWebsocketConnection


class NoDelayConnection(ZMQChannelsWebsocketConnection):
    """The default kernel websocket connection, with no-delay set on its socket."""

    def connect(self) -> asyncio.Future[None] | None:
        """Set no-delay on the open websocket, then connect it to the kernel."""
        self.websocket_handler.set_nodelay(True)
        return super().connect()
