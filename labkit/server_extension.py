"""labkit's Jupyter server extension: the kernel's messages reach the browser without Nagle's delay.

A Jupyter server writes the kernel's messages to the browser's websocket as they come. Tornado leaves
Nagle's algorithm on for a websocket (``set_nodelay`` is off unless a handler asks), so when the kernel
answers a slider move with two messages in a row ("busy", then the widget's new state) the second
waits in the server until the browser acknowledges the first, and a browser on Linux delays that
acknowledgement by up to 40 ms. Measured on the development machine through a real server, one move of
the pchip explorer took 5-11 ms from the comm message to the scene when Nagle was off, and 47-48 ms in
about a third of the moves when it was on (``docs/performance.md``).

:func:`_load_jupyter_server_extension` therefore replaces the server's kernel websocket connection
class by a subclass of it whose ``connect`` first switches Nagle off on that websocket. It subclasses
whatever class the server was configured with (the default one, a gateway's or a course's own), so
nothing else about the connection changes; a server without that setting (Jupyter Server 1) is left
as it is. Installing labkit enables the extension (``etc/jupyter/jupyter_server_config.d/labkit.json``);
``jupyter server extension disable labkit.server_extension`` turns it off.

It also registers a pre-save hook (:func:`drop_unsaved_widget_views`): JupyterLab saves an explorer's
output as a widget view beside its png and html picture, but not the widget's state, so a notebook
reopened later would show "Error displaying widget: model not found" where the picture should be. The
hook leaves out, in the saved file only, every widget view whose state the file does not hold; the
open notebook keeps its live explorer, and the reopened one shows the picture.
"""

from __future__ import annotations

SETTING = "kernel_websocket_connection_class"
WIDGET_VIEW = "application/vnd.jupyter.widget-view+json"
WIDGET_STATE = "application/vnd.jupyter.widget-state+json"


def _jupyter_server_extension_points():
    return [{"module": "labkit.server_extension"}]


def without_nagle(connection_class: type) -> type:
    """A subclass of `connection_class` (named ``NoNagle<its name>``) whose ``connect`` sets TCP_NODELAY on its
    websocket first; a socket that refuses the option connects as before. Given a class this function already
    made, returns it unchanged.
    """
    if getattr(connection_class, "_labkit_nodelay", False):
        return connection_class

    def connect(self):
        handler = getattr(self, "websocket_handler", None)
        log = getattr(self, "log", None)
        try:
            if handler is not None:
                handler.set_nodelay(True)
                if log is not None:
                    log.debug("labkit: this kernel websocket sends without Nagle's delay")
        except (AttributeError, OSError) as exc:  # a handler without the call, a socket already closed
            if log is not None:
                log.debug("labkit: Nagle's algorithm stays on for this kernel websocket (%s)", exc)
        return connection_class.connect(self)

    return type(
        f"NoNagle{connection_class.__name__}",
        (connection_class,),
        {
            "connect": connect,
            "_labkit_nodelay": True,
            "__module__": __name__,
            "__doc__": f"{connection_class.__name__} with Nagle's algorithm off on its websocket (labkit).",
        },
    )


def _saved_widget_models(notebook: dict) -> set:
    """The ids of the widget models whose state a notebook's metadata holds."""
    widgets = (notebook.get("metadata") or {}).get("widgets") or {}
    state = (widgets.get(WIDGET_STATE) or {}).get("state") if isinstance(widgets, dict) else None
    return set(state) if isinstance(state, dict) else set()


def without_unsaved_views(notebook: dict) -> int:
    """Leave out of `notebook` (nbformat 4 as JSON, in place) every output's widget view whose model's state
    it does not hold, where the output has something else to show (a png, html, text); how many were left out.
    """
    saved, dropped = _saved_widget_models(notebook), 0
    for cell in notebook.get("cells") or []:
        outputs = cell.get("outputs") if isinstance(cell, dict) else None
        for output in outputs if isinstance(outputs, list) else []:
            data = output.get("data") if isinstance(output, dict) else None
            if not isinstance(data, dict) or WIDGET_VIEW not in data or len(data) < 2:
                continue
            view = data[WIDGET_VIEW]
            if not isinstance(view, dict) or view.get("model_id") not in saved:
                del data[WIDGET_VIEW]
                dropped += 1
    return dropped


def drop_unsaved_widget_views(model=None, path="", contents_manager=None, **kwargs) -> None:
    """Jupyter Server's pre-save hook: a notebook is saved without widget views it cannot show again
    (:func:`without_unsaved_views`); anything else is saved as it is."""
    if not isinstance(model, dict) or model.get("type") != "notebook" or not isinstance(model.get("content"), dict):
        return
    dropped = without_unsaved_views(model["content"])
    log = getattr(contents_manager, "log", None)
    if dropped and log is not None:
        log.debug("labkit: %s saved with its explorers' pictures instead of %d widget view(s)", path, dropped)


def _load_jupyter_server_extension(serverapp) -> None:
    register = getattr(getattr(serverapp, "contents_manager", None), "register_pre_save_hook", None)
    if register is not None:  # Jupyter Server 2
        register(drop_unsaved_widget_views)
    settings = serverapp.web_app.settings
    current = settings.get(SETTING) or getattr(serverapp, SETTING, None)
    if isinstance(current, str):  # a class named in the configuration, not yet imported
        from traitlets.utils.importstring import import_item

        current = import_item(current)
    if not isinstance(current, type):
        serverapp.log.info("labkit: this server names no kernel websocket class; Nagle's algorithm is left as it is")
        return
    settings[SETTING] = without_nagle(current)
    serverapp.log.info("labkit: kernel websockets send without Nagle's delay (%s)", current.__name__)
