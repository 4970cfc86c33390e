"""labkit's Jupyter server extension (labkit/server_extension.py): the kernel websocket without Nagle's delay.

The unit tests give the extension stand-ins of a server and a websocket; the last one starts a real JupyterLab
server as `make lab` does (the venv's configuration) and opens a kernel's websocket through it.
"""

import asyncio
import json
import sys
import tomllib
from pathlib import Path

import pytest

from labkit import server_extension
from labkit.server_extension import SETTING, _load_jupyter_server_extension, without_nagle

ROOT = Path(__file__).resolve().parents[2]
CONFIG = ROOT / "jupyter" / "jupyter_server_config.d" / "labkit.json"


class Handler:
    def __init__(self):
        self.nodelay = []

    def set_nodelay(self, value):
        self.nodelay.append(value)


class Connection:
    """A connection class as a server has one: ``connect`` is what opens the kernel's channels."""

    def __init__(self, handler):
        self.websocket_handler = handler
        self.order = []

    def connect(self):
        self.order.append(("connect", list(self.websocket_handler.nodelay)))
        return "connected"


class Log:
    def __init__(self):
        self.lines = []

    def info(self, message, *args):
        self.lines.append(message % args)


class App:
    def __init__(self, connection_class):
        self.web_app = type("WebApp", (), {})()
        self.web_app.settings = {SETTING: connection_class}
        self.kernel_websocket_connection_class = connection_class
        self.log = Log()


def test_the_websocket_sends_without_nagle_before_the_kernels_channels_open():
    wrapped = without_nagle(Connection)
    assert issubclass(wrapped, Connection) and wrapped is not Connection and wrapped.__name__ == "NoNagleConnection"
    handler = Handler()
    connection = wrapped(handler)
    assert connection.connect() == "connected"  # the class's own connect still runs, and its result is kept
    assert handler.nodelay == [True] and connection.order == [("connect", [True])]
    assert without_nagle(wrapped) is wrapped  # never wrapped twice


def test_a_connection_without_a_websocket_handler_connects_as_before():
    class Bare:
        websocket_handler = None

        def connect(self):
            return "bare"

    assert without_nagle(Bare)().connect() == "bare"


@pytest.mark.parametrize("configured", ["default", "custom", "named", "only on the app"])
def test_the_extension_wraps_whatever_connection_class_the_server_has(configured):
    from jupyter_server.services.kernels.connection.channels import ZMQChannelsWebsocketConnection

    classes = {
        "default": ZMQChannelsWebsocketConnection,
        "custom": Connection,
        "named": "jupyter_server.services.kernels.connection.channels.ZMQChannelsWebsocketConnection",
    }
    classes["only on the app"] = ZMQChannelsWebsocketConnection
    app = App(classes[configured])
    if configured == "only on the app":  # the web app's settings lack it: the server's own trait is used
        del app.web_app.settings[SETTING]
    _load_jupyter_server_extension(app)
    now = app.web_app.settings[SETTING]
    base = Connection if configured == "custom" else ZMQChannelsWebsocketConnection
    assert issubclass(now, base) and now is not base and getattr(now, "_labkit_nodelay", False)
    assert any("without Nagle's delay" in line for line in app.log.lines)


def test_a_server_without_the_setting_is_left_as_it_is():
    app = App(None)
    app.web_app.settings.clear()
    del app.kernel_websocket_connection_class
    _load_jupyter_server_extension(app)
    assert SETTING not in app.web_app.settings and "left as it is" in app.log.lines[-1]


def test_a_socket_that_refuses_the_option_still_connects():
    class Closed(Handler):
        def set_nodelay(self, value):
            raise OSError("socket closed")

    assert without_nagle(Connection)(Closed()).connect() == "connected"


def test_installing_labkit_enables_the_extension():
    """The wheel's data file, the Makefile's copy into .venv and Binder's postBuild all carry the same config."""
    assert json.loads(CONFIG.read_text())["ServerApp"]["jpserver_extensions"] == {"labkit.server_extension": True}
    files = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["data-files"]
    assert files["etc/jupyter/jupyter_server_config.d"] == ["jupyter/jupyter_server_config.d/labkit.json"]
    target = "etc/jupyter/jupyter_server_config.d/labkit.json"
    assert f"cp jupyter/jupyter_server_config.d/labkit.json $(VENV)/{target}" in (ROOT / "Makefile").read_text()
    assert "jupyter/jupyter_server_config.d/labkit.json" in (ROOT / "postBuild").read_text()
    assert server_extension._jupyter_server_extension_points() == [{"module": "labkit.server_extension"}]


@pytest.mark.slow
def test_a_real_server_in_this_environment_loads_it_and_a_kernels_websocket_connects_through_it(tmp_path):
    """JupyterLab started as `make lab` starts it (this environment's configuration, nothing on its command line)
    loads the extension, and a kernel's websocket connects through the wrapped class and is answered."""

    from tornado.websocket import websocket_connect

    sys.path.insert(0, str(ROOT / "tests" / "browser"))
    try:
        from jupyterlab_session import jupyterlab, kernel_channels
    finally:
        sys.path.pop(0)
    if not (Path(sys.prefix) / "etc/jupyter/jupyter_server_config.d/labkit.json").exists():
        pytest.skip("labkit's server config is not installed in this environment (make installs it in .venv)")
    served = tmp_path / "served"
    served.mkdir()
    with jupyterlab(tmp_path, served, "--log-level=DEBUG") as base:
        url = kernel_channels(base)

        async def kernel_info():
            socket = await websocket_connect(url)
            header = {"msg_id": "labkit-1", "msg_type": "kernel_info_request", "username": "", "session": "s"}
            request = {"header": header, "parent_header": {}, "metadata": {}, "content": {}, "channel": "shell"}
            await socket.write_message(json.dumps(request))
            try:
                while True:
                    reply = await asyncio.wait_for(socket.read_message(), 60)
                    if isinstance(reply, str) and json.loads(reply)["msg_type"] == "kernel_info_reply":
                        return json.loads(reply)["content"]
            finally:
                socket.close()

        assert asyncio.run(kernel_info())["status"] == "ok"
    log = (tmp_path / "server.log").read_text()
    assert "labkit: kernel websockets send without Nagle's delay (ZMQChannelsWebsocketConnection)" in log
    assert "labkit: this kernel websocket sends without Nagle's delay" in log


# --- a saved notebook reopens with its explorers' pictures, never "Error displaying widget" ---------------------


def _explorer_notebook(saved_state=False):
    """A notebook whose one output is an explorer's: a widget view beside its png, html and text."""
    data = {
        server_extension.WIDGET_VIEW: {"model_id": "m1", "version_major": 2, "version_minor": 0},
        "image/png": "iVBORw0KGgo=",
        "text/html": '<img alt="a mesh">',
        "text/plain": "Explorer()",
    }
    output = {"output_type": "display_data", "data": data, "metadata": {}}
    cell = {"cell_type": "code", "id": "c1", "source": "plots.mesh_explorer()", "metadata": {}, "outputs": [output]}
    cell["execution_count"] = 1
    only_view = {"output_type": "display_data", "data": {server_extension.WIDGET_VIEW: {"model_id": "m2"}}}
    cell["outputs"].append({**only_view, "metadata": {}})
    metadata = {}
    if saved_state:
        metadata["widgets"] = {server_extension.WIDGET_STATE: {"state": {"m1": {"model_name": "X"}}}}
    return {"cells": [cell], "metadata": metadata, "nbformat": 4, "nbformat_minor": 5}


def test_a_widget_view_without_its_state_is_left_out_and_the_picture_kept():
    notebook = _explorer_notebook()
    assert server_extension.without_unsaved_views(notebook) == 1
    first, only_view = notebook["cells"][0]["outputs"]
    assert set(first["data"]) == {"image/png", "text/html", "text/plain"}
    assert server_extension.WIDGET_VIEW in only_view["data"]  # nothing else to show: kept as it was
    kept = _explorer_notebook(saved_state=True)  # the state saved ("Save Widget State Automatically")
    assert server_extension.without_unsaved_views(kept) == 0
    assert server_extension.WIDGET_VIEW in kept["cells"][0]["outputs"][0]["data"]


def test_the_servers_contents_manager_saves_notebooks_without_unsaved_views(tmp_path):
    from jupyter_server.services.contents.filemanager import FileContentsManager

    manager = FileContentsManager(root_dir=str(tmp_path))
    app = App(None)
    app.contents_manager = manager
    _load_jupyter_server_extension(app)
    manager.save({"type": "notebook", "format": "json", "content": _explorer_notebook()}, "lab.ipynb")
    saved = json.loads((tmp_path / "lab.ipynb").read_text())
    assert set(saved["cells"][0]["outputs"][0]["data"]) == {"image/png", "text/html", "text/plain"}
    manager.save({"type": "file", "format": "text", "content": "notes"}, "notes.txt")  # other files as they are
    assert (tmp_path / "notes.txt").read_text() == "notes"


def test_a_notebook_of_odd_shape_is_saved_as_it_is():
    odd = {"cells": ["text", {"outputs": "none"}, {"outputs": [1, {"data": []}, {"data": {"text/plain": "x"}}]}]}
    before = json.dumps(odd)
    assert server_extension.without_unsaved_views(odd) == 0 and json.dumps(odd) == before
    server_extension.drop_unsaved_widget_views({"type": "notebook", "content": None}, "x.ipynb")  # nothing to do
