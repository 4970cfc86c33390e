"""Sandbox backends: where a student's notebook runs while it is graded.

Grading knows a backend only through :class:`~.base.Backend`. Built in: ``bwrap`` (the default) and ``none``. A
new backend is one module ``backends/<name>.py`` with a :func:`register`-ed subclass named ``<name>``; one
registered outside labkit works too: each grading process imports its module (:func:`origin`,
:func:`import_origin`).
"""

import importlib
import importlib.util
import pkgutil
import sys

from ....errors import InputError

DEFAULT = "bwrap"
# one module each, backends/<name>.py, found in this package (the default first)
_FOUND = sorted(module.name for module in pkgutil.iter_modules(__path__) if module.name != "base")
BUILTIN = tuple(sorted(_FOUND, key=lambda name: name != DEFAULT))
UNCONFINED = "none"  # the backend the old switch --no-sandbox stands for

_registered: dict = {}  # name -> Backend subclass


def register(cls):
    """Make the Backend subclass `cls` available under ``cls.name`` (use as a class decorator)."""
    from .base import Backend

    if not (isinstance(cls, type) and issubclass(cls, Backend)):
        raise InputError(
            f"{cls!r} is not a subclass of labkit.grading.sandbox.backends.base.Backend; "
            "only backends can be registered."
        )
    name = getattr(cls, "name", None)
    if not isinstance(name, str) or not name.isidentifier() or name != name.lower():
        raise InputError(
            f"{cls.__qualname__}.name is {name!r}; a backend needs a lower-case name that is a Python "
            "identifier, e.g. name = 'podman' (it is what `labkit grade --sandbox` takes)."
        )
    known = _registered.get(name)
    if known is not None and (known.__module__, known.__qualname__) != (cls.__module__, cls.__qualname__):
        raise InputError(
            f"a backend named {name!r} is already registered ({known.__module__}.{known.__qualname__}); "
            f"give {cls.__qualname__} another name."
        )
    _registered[name] = cls
    return cls


def names():
    """Every backend's name: the built-in ones in order (the default first), then any registered later."""
    return BUILTIN + tuple(sorted(set(_registered) - set(BUILTIN)))


def backend_class(name):
    """The Backend subclass called `name`; ValueError listing the choices for a name there is none of."""
    if isinstance(name, str) and name in BUILTIN and name not in _registered:
        importlib.import_module(f"{__name__}.{name}")  # the module registers its backend
    if not isinstance(name, str) or name not in _registered:
        raise InputError(
            f"there is no sandbox backend called {name!r}; choose one of: {', '.join(names())} "
            f"(e.g. `labkit grade --sandbox {DEFAULT}`, the default)."
        )
    return _registered[name]


def get_backend(name):
    """A new instance of the backend called `name`; ValueError listing the choices for a name there is none of."""
    return backend_class(name)()


def origin(name):
    """(module name, file) where backend `name` is defined, so that another process can import it."""
    module = backend_class(name).__module__
    return module, getattr(sys.modules[module], "__file__", None)


def import_origin(module, path=None):
    """Import `module` (by name, or else from the file `path`) so that the backend it registers is known here."""
    if module in sys.modules:
        return
    try:
        importlib.import_module(module)
        return
    except ImportError:
        if not path:
            raise InputError(
                f"cannot import {module!r}, which defines the sandbox backend; make it importable "
                "(on PYTHONPATH, or installed) in the grading processes."
            ) from None
    spec = importlib.util.spec_from_file_location(module, path)
    if spec is None or spec.loader is None:
        raise InputError(f"cannot import the sandbox backend's module {module!r} from {path}.")
    loaded = importlib.util.module_from_spec(spec)
    sys.modules[module] = loaded
    try:
        spec.loader.exec_module(loaded)
    except BaseException:
        del sys.modules[module]
        raise
