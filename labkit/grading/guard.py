"""The watch over a notebook's process while it is graded (the sandbox's side).

The notebook's process is the student's: anything its cells leave behind
(a patched module, a saved code object, a helper that rewrites labkit's own
grading code) is in it. So the watch is installed before the first cell
runs, by the pristine process that forks the notebook's
(:mod:`labkit.grading.worker`), and it is reachable afterwards only through
the interpreter's profile hook:

* **while the cells run** it lets everything happen but notes *tampering*:
  reading or replacing the profile hook, walking the garbage collector,
  starting a thread or a process. Any of these voids every answer the
  notebook gives later, because the watch can no longer vouch for them;
* **while a graded call runs** (between two sentinel calls made by the
  worker's own serving code, recognised by their pristine code objects) it
  also notes every call of a refused reference: any Python function whose
  code is one of the refused modules' functions, recognised by a digest of
  its code that the grader computed from the library's files (so a
  subclass, a saved code object, ``construct_fast``, a private helper or a
  pasted copy of the code is caught alike), and any compiled function of a
  refused module that Python code calls directly. Compiled functions and
  classes of the refused modules are also replaced in their modules for
  the length of the call;
* at the end of each answer it writes an *attestation* to a pipe only the
  pristine worker reads: the request, whether the call stayed clean (or
  the first refused reference, or the tampering), and a digest of the
  answer, signed with a key that never existed in the notebook's memory
  outside the watch. The worker forwards an answer only with a valid
  attestation, so an answer forged by the notebook, or given after the
  watch was switched off, never reaches the grader.

Nothing here raises into the student's code: a refused call is allowed to
run and the answer is voided afterwards (raising from a profile hook would
switch it off).
"""
import hashlib
import hmac
import os
import sys
import types

SMALL_CODE = 64  # bytes of bytecode below which a function is only recognised with its name and place


def code_key(code):
    """A digest of a function's code that survives renaming the function but not rewriting it.

    Bytecode, the names and local names it uses and its numeric constants;
    short functions (which an honest student might write identically) are
    also keyed by their name, file and line.
    """
    consts = tuple(c for c in code.co_consts if isinstance(c, (int, float, complex, type(None))) and c is not True
                   and c is not False)
    digest = hashlib.sha1(code.co_code)
    digest.update(repr((code.co_names, code.co_varnames, code.co_argcount, consts)).encode())
    if len(code.co_code) < SMALL_CODE:
        digest.update(repr((code.co_qualname, code.co_filename, code.co_firstlineno)).encode())
    return digest.digest()[:12]


def codes_in(code):
    """A code object and every code object nested in it (functions, methods, comprehensions)."""
    yield code
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            yield from codes_in(const)


def sign(secret, *parts):
    """The attestation's signature over its parts."""
    return hmac.new(secret, "\x1f".join(map(str, parts)).encode(), hashlib.sha256).hexdigest()


RUN = "run"  # the profile of the request that runs the cells: nothing is refused, tampering is noted
STRICTEST = "strictest"  # what is refused before a request has said which profile it needs


def begin_request():
    """Sentinel: the serving code is about to read a request (the watch starts watching strictly)."""


def chosen(rid, profile, passables, handoff):
    """Sentinel: the request read is `rid`, to be answered under `profile`, handing `passables` to student code."""


def end_request(payload):
    """Sentinel: the encoded answer (the watch attests it)."""


def attestation_text(rid, profile, passables, status, digest):
    """The fields of one attestation, as signed."""
    return rid, profile or "", ",".join(sorted(passables)), status, digest


def _tamper_targets():
    """Builtins whose use while the notebook is watched voids its answers, by identity: {id: (object, name)}.

    The second set is tampering only during a graded call (an honest cell may collect garbage)."""
    import _thread
    import gc
    import posix
    import signal

    always = {sys.setprofile: "sys.setprofile", sys.getprofile: "sys.getprofile", sys.settrace: "sys.settrace",
              sys.gettrace: "sys.gettrace", sys.addaudithook: "sys.addaudithook", gc.get_objects: "gc.get_objects",
              gc.get_referrers: "gc.get_referrers", gc.get_referents: "gc.get_referents",
              signal.signal: "signal.signal", _thread.start_new_thread: "a new thread (_thread.start_new_thread)"}
    for name in ("fork", "forkpty", "posix_spawn", "posix_spawnp", "system", "execv", "execve"):
        if hasattr(posix, name):
            always[getattr(posix, name)] = f"a new process (os.{name})"
    try:
        import _posixsubprocess

        always[_posixsubprocess.fork_exec] = "a new process (subprocess)"
    except ImportError:
        pass
    graded = {gc.enable: "gc.enable", gc.collect: "gc.collect"}
    return ({id(obj): (obj, name) for obj, name in always.items()},
            {id(obj): (obj, name) for obj, name in graded.items()})


class _Refused:
    """Stands in for a refused compiled function or class while a graded call runs."""

    def __init__(self, name):
        self.name = name

    def __call__(self, *args, **kwargs):
        raise RuntimeError(f"{self.name} is switched off while this exercise is graded: "
                           "the exercise asks you to write it yourself")


def _compiled(value):
    """Whether `value` is a compiled function or a class with no Python methods (it has no code to key)."""
    if isinstance(value, types.BuiltinFunctionType) or type(value).__name__ in (
            "cython_function_or_method", "fused_cython_function", "fortran"):
        return True
    if isinstance(value, type):
        return not any(isinstance(v, (types.FunctionType, classmethod, staticmethod, property))
                       for v in vars(value).values())
    return False


def _within(module, prefixes):
    return any(module == p or module.startswith(p + ".") for p in prefixes)


def _plain(value):
    """An argument for a trusted function: plain float arrays and floats (the student's hooks run here)."""
    import numpy as np

    array = np.array(value, dtype=float)
    return float(array) if array.ndim == 0 else array


def _handed_over(copy):
    """The function student code gets for a trusted copy: its arguments become plain numbers before the
    copy runs, and a function among them runs behind a barrier (untrusted) when the copy calls it."""

    def handed_over(*args, **kwargs):
        args = tuple(_barrier(a) if callable(a) else _plain(a) for a in args)
        kwargs = {k: _barrier(v) if callable(v) else _plain(v) for k, v in kwargs.items()}
        return copy(*args, **kwargs)

    handed_over.__name__, handed_over.__qualname__ = copy.__name__, copy.__qualname__
    handed_over.__doc__ = copy.__doc__
    return handed_over


def _barrier(function):
    def barrier(*args, **kwargs):
        return function(*args, **kwargs)

    return barrier


def install(secret, verdict_fd, profiles, passables, chain):
    """Install the watch in this (still pristine) process; afterwards only the profile hook holds it.

    `profiles` maps a profile name to ``(names, modules, c_names)``: the refused
    Python code as {digest: readable name} (:func:`code_key`), the refused
    module prefixes (their compiled functions are refused, and replaced
    during a call) and single refused compiled functions ``(module, name)``.
    `passables` maps the names the grader may hand to student code to
    pristine functions: the watch makes each a copy with a code object of its
    own, trusted during the request it is handed to, when it is called
    through the function handed over (which turns its arguments into plain
    numbers first). Only the copy's own code is trusted, not what it calls.
    `chain` is the pristine code of the serving functions, innermost first,
    that must call the sentinels.
    """
    import gc

    write, gc_disable, gc_enable, sha256 = os.write, gc.disable, gc.enable, hashlib.sha256
    key_of, signed, within, fields = code_key, sign, _within, attestation_text
    begin_code, chosen_code, end_code = begin_request.__code__, chosen.__code__, end_request.__code__
    refused_call = _Refused.__call__.__code__
    handed_code = _handed_over(lambda: None).__code__
    tamper_always, tamper_graded = _tamper_targets()
    union = ({}, set(), set())
    for names, modules, c_names in profiles.values():
        union[0].update(names)
        union[1].update(modules)
        union[2].update(c_names)
    strictest = (union[0], tuple(union[1]), frozenset(union[2]))
    copies = {}
    for name, function in passables.items():
        code = function.__code__.replace()  # equal, but another object: trusted by identity
        copy = types.FunctionType(code, function.__globals__, function.__name__, function.__defaults__,
                                  function.__closure__)
        copy.__kwdefaults__, copy.__qualname__ = function.__kwdefaults__, function.__qualname__
        copies[name] = (code, _handed_over(copy))
    state = {"mode": "idle", "rid": None, "name": None, "profile": None, "passables": (), "refused": None,
             "tampered": None, "live": frozenset(), "stubbed": []}
    cache = {}  # id(code) -> (code, key)

    def key(code):
        found = cache.get(id(code))
        if found is None or found[0] is not code:
            found = (code, key_of(code))
            cache[id(code)] = found
        return found[1]

    def genuine(frame):
        caller = frame.f_back
        for expected in chain:
            if caller is None or caller.f_code is not expected:
                return False
            caller = caller.f_back
        return True

    def note_tampering(what):
        if state["tampered"] is None:
            state["tampered"] = what

    def stub(profile):
        modules, c_names = profile[1], profile[2]
        for module_name, module in list(sys.modules.items()):
            namespace = getattr(module, "__dict__", None) if type(module) is types.ModuleType else None
            if namespace is None:
                continue
            whole = within(module_name, modules)
            for attribute, value in list(namespace.items()):
                if (module_name, attribute) in c_names or (
                        whole and _compiled(value) and within(str(getattr(value, "__module__", "") or module_name),
                                                              modules)):
                    namespace[attribute] = _Refused(f"{module_name}.{attribute}")
                    state["stubbed"].append((namespace, attribute, value))

    def begin(frame):
        if not genuine(frame):
            return
        if state["mode"] != "idle":
            note_tampering("a grading request started inside another")
        state.update(mode="reading", rid=None, name=None, profile=strictest, passables=(), refused=None,
                     live=frozenset())

    def choose(frame):
        if not genuine(frame):
            return
        if state["mode"] != "reading":
            note_tampering("a grading request chosen twice")
            return
        local = frame.f_locals
        name, handoff = local["profile"], local["handoff"]
        wanted = tuple(str(n) for n in local["passables"])
        live = set()
        for passable in wanted:
            if passable in copies:
                code, handed = copies[passable]
                handoff[passable] = handed
                live.add(code)
        profile = None if name in (None, RUN) else profiles.get(name, strictest)
        state.update(rid=str(local["rid"]), name=name, profile=profile, passables=wanted, live=frozenset(live),
                     mode=RUN if name == RUN else "graded")
        if state["mode"] == RUN:
            gc_enable()  # the cells run as in a kernel
        elif profile is not None:
            stub(profile)

    def end(frame):
        if not genuine(frame) or state["mode"] not in ("graded", RUN):
            return
        payload = frame.f_locals["payload"]
        for namespace, attribute, value in reversed(state["stubbed"]):
            namespace[attribute] = value
        state["stubbed"].clear()
        status = (f"tampered:{state['tampered']}" if state["tampered"] else
                  f"refused:{state['refused']}" if state["refused"] else "clean")
        parts = fields(state["rid"], state["name"], state["passables"], status, sha256(payload).hexdigest())
        state.update(mode="idle", rid=None, name=None, profile=None, passables=(), live=frozenset())
        write(verdict_fd, ("\t".join(parts) + "\t" + signed(secret, *parts) + "\n").encode())

    def hook(frame, event, arg):
        try:
            if event == "c_call":
                found = tamper_always.get(id(arg))
                if found is None and state["mode"] in ("reading", "graded"):
                    found = tamper_graded.get(id(arg))
                if found is not None and found[0] is arg:
                    note_tampering(found[1])
                elif state["profile"] is not None and state["mode"] in ("reading", "graded") \
                        and state["refused"] is None:
                    owner = getattr(arg, "__self__", None)
                    module = getattr(arg, "__module__", None)
                    if type(module) is not str:
                        module = owner.__name__ if type(owner) is types.ModuleType else ""
                    name = getattr(arg, "__name__", "")
                    profile = state["profile"]
                    if (module, name) in profile[2] or within(module, profile[1]):
                        state["refused"] = f"{module}.{name}"
            elif event == "call":
                code = frame.f_code
                if code is begin_code:
                    gc_disable()  # no finalizer of the student's runs while the watch's frames are on the stack
                    begin(frame)
                elif code is chosen_code:
                    choose(frame)
                elif code is end_code:
                    end(frame)
                    gc_enable()
                elif state["mode"] in ("reading", "graded") and state["refused"] is None:
                    profile = state["profile"]
                    if code is refused_call:
                        refused_name = frame.f_locals["self"].name
                    else:
                        refused_name = profile[0].get(key(code)) if profile is not None else None
                    if refused_name is not None and not (code in state["live"] and frame.f_back is not None
                                                         and frame.f_back.f_code is handed_code):
                        state["refused"] = refused_name
        except BaseException:  # noqa: BLE001 - the hook must never raise (that would switch it off)
            note_tampering("an error inside the grader's watch (RecursionError or MemoryError?)")

    sys.setprofile(hook)


def unwire(profiles):
    """The profiles the grader sent (:func:`labkit.grading.refusals.wire`) as :func:`install` takes them."""
    return {name: ({bytes.fromhex(key): text for key, text in profile["names"].items()},
                   tuple(profile["modules"]), frozenset(tuple(pair) for pair in profile["c_names"]))
            for name, profile in profiles.items()}
