"""The watch over a notebook's process while it is graded (the sandbox's side).

The pristine supervisor (:mod:`labkit.grading.sandbox.worker`) installs it before the first cell, and nothing of
it is reachable from Python afterwards. An **audit hook** (it cannot be removed or listed) holds its state and
key, reports *tampering* at once on a pipe the supervisor reads (from then on nothing the notebook does counts),
and takes the worker's sentinels (``labkit.begin``, ``labkit.chosen``, ``labkit.end``) only from the pristine
serving code. During a graded request a **profile hook**, set through the C API, notes every call of a refused
function, recognised by a digest of its code (:func:`code_key`); the refused modules' compiled routines are
replaced for the request. After each answer the audit hook writes a signed **attestation**, and the supervisor
forwards only attested answers.

Neither hook touches a student's object (no attribute, comparison or hash): they read code objects, frames and
exact built-in types, with the garbage collector off, so no student code runs while the watch's frames are on
the stack; seccomp (:mod:`labkit.grading.sandbox.seccomp`) forbids threads and signal handlers that could
interrupt them. Neither hook raises: a refused call runs and its answer is voided.
"""

import _hashlib
import builtins
import gc
import opcode
import os
import sys
import types

# taken at import, in the pristine supervisor, and looked up in a private namespace (:func:`install`): a notebook
# that rebinds ``guard.hashlib``, ``builtins.any`` or ``hashlib.sha1`` changes nothing the watch uses
_sha1, _sha256, _hmac_digest = _hashlib.openssl_sha1, _hashlib.openssl_sha256, _hashlib.hmac_digest
_write, _getframe, _modules = os.write, sys._getframe, sys.modules
_gc_disable, _gc_enable, _gc_isenabled = gc.disable, gc.enable, gc.isenabled
_HASCONST, _EXTENDED_ARG, _NOP = frozenset(opcode.hasconst), opcode.EXTENDED_ARG, opcode.opmap["NOP"]
_NoneType = type(None)
_ModuleType, _CodeType = types.ModuleType, types.CodeType
_FunctionType, _BuiltinFunctionType = types.FunctionType, types.BuiltinFunctionType

_HEAP_TYPE = 1 << 9  # Py_TPFLAGS_HEAPTYPE: a class made by Python code, not a compiled one
SMALL_CODE = 64  # bytes of bytecode below which a function is only recognised with its name and place
RUN = "run"  # the profile of the request that runs the cells: nothing is refused, tampering is noted
BEGIN, CHOSEN, END = "labkit.begin", "labkit.chosen", "labkit.end"  # the worker's sentinels
# audit events that void the notebook's answers: what reaches the watch's state or goes round it
TAMPER_EVENTS = frozenset(
    {"sys.setprofile", "sys.settrace", "sys._current_frames", "sys.addaudithook", "sys.monitoring.register_callback"}
    | {"gc.get_objects", "gc.get_referrers", "gc.get_referents", "gc.freeze"}
    | {"os.fork", "os.forkpty", "os.posix_spawn", "os.exec", "os.spawn", "os.system", "subprocess.Popen"}
    | {"code.__new__", "function.__new__", "_thread.start_new_thread"}
    | {"cpython._PySys_ClearAuditHooks", "cpython.run_interactivehook"}
)
TAMPER_PREFIXES = ("ctypes.",)  # but ctypes.dlopen: scipy's own imports open libraries, which is no harm alone
HARMLESS = frozenset({"ctypes.dlopen"})
GUARDED_ATTRIBUTES = frozenset({"__code__"})  # libraries set __defaults__ and the like when imported
# the functions of this module whose functions student code may hold (see :func:`install`)
EXPOSED = frozenset({"_stand_in", "_plain", "_handed_over", "_barrier"})


def _constant(value):
    """A loaded constant in :func:`code_key`: numbers and None by value, others by kind (exact types only)."""
    kind = type(value)
    if kind is _NoneType or kind is bool:
        return repr(value)
    if kind is int:
        return f"i{value}" if -(1 << 64) < value < 1 << 64 else f"I{value.bit_length()}"
    if kind is float or kind is complex:
        return f"{kind.__name__[0]}{value!r}"
    if kind is tuple:
        return "(" + ",".join([_constant(item) for item in value]) + ")"
    if kind is str:
        return "s"
    if kind is _CodeType:
        return "c"
    return "o"


def code_key(code):
    """A digest of a function's code that survives renaming the function but not rewriting it.

    Bytecode (NOPs left out) with each loaded constant by value (strings by kind only), names, local names and
    argument count: so a deleted or stripped (``optimize=2``) docstring keeps the key. Short functions, which an
    honest student might write identically, are keyed by their name, file and line too.
    """
    raw, consts = code.co_code, code.co_consts
    structure, loaded, count, extended = bytearray(), [], len(consts), 0
    for i in range(0, len(raw) - 1, 2):
        op, arg = raw[i], raw[i + 1] | extended
        extended = (arg << 8) if op == _EXTENDED_ARG else 0
        if op == _NOP:
            continue  # where a statement compiled to nothing stood (a docstring stripped by optimize=2)
        structure.append(op)
        if op in _HASCONST:
            structure.append(0)
            loaded.append(_constant(consts[arg]) if arg < count else "?")
        else:
            structure.append(raw[i + 1])
    digest = _sha1(bytes(structure))
    digest.update(repr((code.co_names, code.co_varnames, code.co_argcount, loaded)).encode())
    if len(raw) < SMALL_CODE:
        digest.update(repr((code.co_qualname, code.co_filename, code.co_firstlineno)).encode())
    return digest.digest()[:12]


def codes_in(code):
    """A code object and every code object nested in it (functions, methods, comprehensions)."""
    yield code
    for const in code.co_consts:
        if type(const) is _CodeType:
            yield from codes_in(const)


def sign(secret, *parts):
    """The attestation's signature over its parts (HMAC-SHA256, computed in C)."""
    return _hmac_digest(secret, "\x1f".join(map(str, parts)).encode(), "sha256").hex()


def attestation_text(rid, profile, passables, status, digest):
    """The fields of one attestation, as signed."""
    return rid, profile or "", ",".join(sorted(passables)), status, digest


def _stand_in(name):
    """A stand-in for a refused compiled function or class; the watch knows its code and reads `name` from its frame."""

    def refused(*args, **kwargs):
        raise RuntimeError(
            f"{name} is switched off while this exercise is graded: the exercise asks you to write it yourself"
        )

    return refused


def _within(module, prefixes):
    return any(module == p or module.startswith(p + ".") for p in prefixes)


def _plain(value):
    """An argument for a trusted function: plain float arrays and floats (the student's hooks run here)."""
    import numpy as np

    array = np.array(value, dtype=float)
    return float(array) if array.ndim == 0 else array


def _handed_over(copy):
    """A trusted copy for student code: arguments become plain numbers, functions run behind an untrusted barrier."""

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


def _compiled_types():
    """The exact types of compiled functions in this process (builtins, Cython and f2py routines)."""
    found = {_BuiltinFunctionType}
    for module in list(_modules.values()):
        namespace = getattr(module, "__dict__", None) if type(module) is _ModuleType else None
        for value in (namespace or {}).values():
            if type(value).__name__ in ("cython_function_or_method", "fused_cython_function", "fortran"):
                found.add(type(value))
    return frozenset(found)


# machine code in front of the profile hook: only 'call' events (what == 0) of code objects not in its table (found
# clean in this request) reach the Python hook, so a notebook pays one hook call per code object, not per call.
# x86-64 System V, CPython 3.11 (frame->f_frame->f_code; checked before use):
#   endbr64; test edx, edx; jne done; mov rax, [rsi+24]; mov rax, [rax+32]; mov r8, rax; shr r8, 4;
#   and r8d, SLOTS-1; movabs r9, TABLE; cmp [r9+r8*8], rax; je done; movabs rax, HOOK; jmp rax; done: xor eax, eax; ret
_CALL_FILTER = (
    "f30f1efa85d27532488b4618488b40204989c049c1e8044181e0ff0f000049b9",
    "4b3904c1740c48b8",
    "ffe031c0c3",
)
SLOTS = 1 << 12  # the filter's table of code objects found clean: the slot of one is (its address >> 4) & (SLOTS - 1)


def _call_filter(hook_address):
    """(the filter's address in front of the hook at `hook_address`, its table, what keeps both alive), or
    (`hook_address`, None, None) where it cannot run: the hook then sees every event. Called while pristine."""
    import ctypes
    import mmap
    import platform

    if platform.machine() != "x86_64" or sys.implementation.name != "cpython" or sys.version_info[:2] != (3, 11):
        return hook_address, None, None
    frame = _getframe()  # does this Python lay frames out as the filter reads them (frame->f_frame->f_code)?
    inner = ctypes.c_void_p.from_address(id(frame) + 24).value
    if inner is None or ctypes.c_void_p.from_address(inner + 32).value != id(frame.f_code):
        return hook_address, None, None
    table = (ctypes.c_uint64 * SLOTS)()
    table_at, hook_at = (address.to_bytes(8, "little") for address in (ctypes.addressof(table), hook_address))
    head, middle, tail = (bytes.fromhex(part) for part in _CALL_FILTER)
    code = head + table_at + middle + hook_at + tail
    try:
        page = mmap.mmap(-1, mmap.PAGESIZE, prot=mmap.PROT_READ | mmap.PROT_WRITE)
        page.write(code)
        view = ctypes.c_char.from_buffer(page)
        mprotect = ctypes.CDLL(None).mprotect
        mprotect.argtypes, mprotect.restype = (ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int), ctypes.c_int
        if mprotect(ctypes.addressof(view), mmap.PAGESIZE, mmap.PROT_READ | mmap.PROT_EXEC) != 0:
            return hook_address, None, None  # no executable memory here (a hardened kernel): the plain hook
    except (OSError, ValueError, AttributeError):
        return hook_address, None, None
    return ctypes.addressof(view), table, (page, view, table)


def install(secret, verdict_fd, profiles, passables, chain):
    """Install the watch in this (still pristine) process; afterwards nothing of it is reachable from Python.

    Its code runs in a private copy of this module's namespace and builtins, so no name it looks up can be
    rebound by a notebook; the functions student code can hold (:data:`EXPOSED`) get another copy, so their
    ``__globals__`` lead nowhere. `profiles`: as :func:`unwire` returns them. `passables`: name -> pristine
    function, trusted (not what it calls) only during its request and only through the function handed over.
    `chain`: the pristine code of the serving functions, innermost first, that must raise the sentinels.
    """
    private = dict(globals())
    private["__builtins__"] = dict(vars(builtins))
    exposed = {"__name__": __name__, "__builtins__": dict(vars(builtins))}
    for name, value in list(private.items()):
        if type(value) is _FunctionType and value.__globals__ is globals():
            home = exposed if name in EXPOSED else private
            home[name] = private[name] = _FunctionType(
                value.__code__, home, value.__name__, value.__defaults__, value.__closure__
            )
    private["_install"](secret, verdict_fd, profiles, passables, chain)


def _install(secret, verdict_fd, profiles, passables, chain):
    """The watch itself, run in the private namespace; its state is one dict only the hooks' closures hold."""
    import ctypes

    strictest = _strictest(profiles)
    c_objects = _refused_objects([*profiles.values(), strictest])
    sizes, holders = _modules_as_found(c_objects)
    # what the watch was given, and what it took while the process was pristine
    state = dict(secret=secret, verdict_fd=verdict_fd, chain=chain, profiles=profiles, strictest=strictest)
    state.update(c_objects=c_objects, sizes=sizes, holders=holders, copies=_trusted_copies(passables))
    state.update(compiled_types=_compiled_types(), refused_call=_stand_in("").__code__)
    state.update(handed_code=_handed_over(lambda: None).__code__, cache={})  # cache: id(code) -> (code, key)
    # the request: mode is "idle" between requests, "reading" after begin, "graded" during a call, RUN during the cells
    state.update(mode="idle", rid=None, name=None, profile=None, passables=(), refused=None, tampered=None)
    # held: the code objects in the filter's table, alive until it is emptied: no other code takes their address
    state.update(live=frozenset(), stubbed=[], busy=False, gc=True, held=[])
    hook_type = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.py_object, ctypes.c_int, ctypes.c_void_p)
    hook = hook_type(_profile_hook(state))
    set_profile = ctypes.pythonapi.PyEval_SetProfile
    set_profile.argtypes, set_profile.restype = (ctypes.c_void_p, ctypes.c_void_p), None
    hook_address, seen, page = _call_filter(ctypes.cast(hook, ctypes.c_void_p).value)
    state.update(set_profile=set_profile, hook_address=hook_address, seen=seen, memset=ctypes.memset)
    audit = _audit_hook(state)
    # the C callback and its filter live as long as the audit hook, which lives as long as the process
    audit.keep = (hook, page)
    sys.addaudithook(audit)


def _strictest(profiles):
    """The strictest profile: every profile's refusals together."""
    kept = profiles.values()
    names = {key: text for each, _, _ in kept for key, text in each.items()}
    mods = tuple({prefix for _, each, _ in kept for prefix in each})
    return names, mods, frozenset().union(*(each for _, _, each in kept))


def _refused_objects(profiles):
    """The refused compiled functions themselves, taken while the process is pristine: {c_names: {id: (it, name)}}."""
    c_objects = {}
    for _names, _mods, c_names in profiles:
        found = {}
        for module_name, attribute in c_names:
            module = _modules.get(module_name)
            namespace = module.__dict__ if type(module) is _ModuleType else {}
            if attribute in namespace:
                found[id(namespace[attribute])] = (namespace[attribute], f"{module_name}.{attribute}")
        c_objects[c_names] = found
    return c_objects


def _modules_as_found(c_objects):
    """The modules as the watch found them: how many names each held, and which held a refused compiled function."""
    sizes, holders, every_target = {}, set(), frozenset(i for found in c_objects.values() for i in found)
    for module_name, module in list(_modules.items()):
        if type(module_name) is str and type(module) is _ModuleType and type(module.__dict__) is dict:
            sizes[module_name] = len(module.__dict__)
            if not every_target.isdisjoint(map(id, module.__dict__.values())):
                holders.add(module_name)
    return sizes, holders


def _trusted_copies(passables):
    """{name: (the code trusted, the function handed over)} for each function the grader may hand to student code."""
    copies = {}
    for name, function in passables.items():
        code = function.__code__.replace()  # equal, but another object: trusted by identity
        copy = _FunctionType(code, function.__globals__, function.__name__, function.__defaults__, function.__closure__)
        copy.__kwdefaults__, copy.__qualname__ = function.__kwdefaults__, function.__qualname__
        copies[name] = (code, _handed_over(copy))
    return copies


def _note_tampering(state, what):
    if state["tampered"] is None:
        state["tampered"] = what
    try:
        _write(state["verdict_fd"], f"TAMPER\t{what}\n".encode())
    except OSError:
        pass


def _note_busy(state, what):
    """:func:`_note_tampering` with the audit hook deaf to what that raises."""
    state["busy"] = True
    try:
        _note_tampering(state, what)
    finally:
        state["busy"] = False


def _genuine(state, caller):
    """Whether the Python frame that raised a sentinel is the worker's own serving chain."""
    for expected in state["chain"]:
        if caller is None or caller.f_code is not expected:
            return False
        caller = caller.f_back
    return True


def _stub(state, profile):
    """Replace the compiled functions and classes of the refused modules (exact types only)."""
    mods, c_names = profile[1], profile[2]
    # a refused compiled function is switched off under every name a module holds it by (numpy's interp is
    # numpy._core._multiarray_umath.interp, numpy._core.multiarray.interp, ...): found by identity only
    targets = state["c_objects"].get(c_names, {})
    target_ids = frozenset(targets)
    for module_name, module in list(_modules.items()):
        if type(module_name) is not str or type(module) is not _ModuleType or type(module.__dict__) is not dict:
            continue
        namespace = module.__dict__
        whole = _within(module_name, mods)
        held = _holds_target(state, module_name, namespace, target_ids)
        if whole or held or any(m == module_name for m, _ in c_names):
            _stub_module(state, module_name, namespace, whole, targets, c_names)


def _holds_target(state, module_name, namespace, target_ids):
    """Whether a module holds a refused compiled function (as at install, or loaded or grown since: ids compared in
    C, so no object of the notebook's is asked anything)."""
    held = module_name in state["holders"]
    if target_ids and not held and state["sizes"].get(module_name) != len(namespace):
        held = not target_ids.isdisjoint(map(id, namespace.values()))
        if not held:
            state["sizes"][module_name] = len(namespace)  # looked at with this many names: again once it changes
    return held


def _stub_module(state, module_name, namespace, whole, targets, c_names):
    """Put stand-ins in one module for what it holds of the refused (its every compiled function when `whole`)."""
    entries = list(namespace.items())
    if any(type(attribute) is not str for attribute, _ in entries):
        # a key of the notebook's making could run code when the dictionary compares it
        _note_tampering(state, f"a name that is not a string put in {module_name}")
        return
    for attribute, value in entries:
        kind = type(value)
        compiled = kind in state["compiled_types"] or (kind is type and not value.__flags__ & _HEAP_TYPE)
        alias = id(value) in targets and targets[id(value)][0] is value
        if ((module_name, attribute) in c_names) or (whole and compiled) or alias:
            name = targets[id(value)][1] if alias else f"{module_name}.{attribute}"
            namespace[attribute] = _stand_in(name)
            state["stubbed"].append((namespace, attribute, value))


def _unstub(state):
    for namespace, attribute, value in reversed(state["stubbed"]):
        namespace[attribute] = value
    state["stubbed"].clear()


def _key(state, code):
    found = state["cache"].get(id(code))
    if found is None or found[0] is not code:
        found = state["cache"][id(code)] = (code, code_key(code))
    return found[1]


def _profile_hook(state):
    """The hook of every profile event of a graded request (called through the C API): refused calls are noted."""
    refused_call, handed_code = state["refused_call"], state["handed_code"]

    def profile_hook(obj, frame, what, arg):
        try:
            if what != 0 or state["refused"] is not None:  # only 'call' events, and only until the first refusal
                return 0
            code = frame.f_code
            profile = state["profile"]
            if code is refused_call:
                name = frame.f_locals.get("name")
                name = name if type(name) is str and name else "a switched-off function"
            else:
                name = profile[0].get(_key(state, code)) if profile is not None else None
            if name is not None and not (
                code in state["live"] and frame.f_back is not None and frame.f_back.f_code is handed_code
            ):
                state["refused"] = str(name)
            elif name is None:
                _remember(state, code)
        except BaseException:  # noqa: BLE001 - the hook never raises (its traceback would expose the watch)
            state["tampered"] = state["tampered"] or "an error inside the grader's watch"
        return 0

    return profile_hook


def _remember(state, code):
    """A code object found clean under this request's profile: the filter passes over its calls from now on."""
    if state["seen"] is not None:
        state["seen"][(id(code) >> 4) & (SLOTS - 1)] = id(code)
        state["held"].append(code)


def _forget(state):
    """Empty the filter's table (a new request, or its profile, starts)."""
    if state["seen"] is not None and state["held"]:
        state["memset"](state["seen"], 0, 8 * SLOTS)  # SLOTS addresses of 8 bytes
        state["held"].clear()


def _begin(state):
    if state["mode"] != "idle":
        _note_tampering(state, "a grading request started inside another")
        return
    state["gc"] = _gc_isenabled()
    _gc_disable()  # no finalizer of the student's runs while a request is watched
    _forget(state)
    state.update(
        mode="reading", rid=None, name=None, profile=state["strictest"], passables=(), refused=None, live=frozenset()
    )
    state["set_profile"](state["hook_address"], None)  # sys.getprofile() stays None: nothing to fetch


def _as_a_worker_sends(rid, name, wanted, handoff):
    """Whether a request's choice has the exact built-in types the worker sends (and an empty handoff)."""
    return not (
        type(rid) is not str
        or (name is not None and type(name) is not str)
        or type(wanted) not in (list, tuple)
        or any(type(w) is not str for w in wanted)
        or type(handoff) is not dict
        or handoff
    )


def _choose(state, args):
    if state["mode"] != "reading" or len(args) != 4:
        _note_tampering(state, "a grading request chosen twice")
        return
    rid, name, wanted, handoff = args
    if not _as_a_worker_sends(rid, name, wanted, handoff):
        _note_tampering(state, "a grading request with what no grader sends")
        return
    live = set()
    for passable in wanted:
        if passable in state["copies"]:
            code, handed = state["copies"][passable]
            handoff[passable] = handed
            live.add(code)
    profile = None if name in (None, RUN) else state["profiles"].get(name, state["strictest"])
    state.update(rid=rid, name=name, profile=profile, passables=tuple(wanted), live=frozenset(live))
    state["mode"] = RUN if name == RUN else "graded"
    # cells: watched for tampering only, at full speed; the walk over the modules runs unprofiled (no student code)
    state["set_profile"](None, None)
    if name == RUN:
        if state["gc"]:
            _gc_enable()
    elif profile is not None:
        _stub(state, profile)
        _forget(state)  # what was clean while the request was read is judged again under its own profile
        state["set_profile"](state["hook_address"], None)


def _end(state, args):
    if state["mode"] not in ("graded", RUN) or len(args) != 1 or type(args[0]) is not bytes:
        _note_tampering(state, "an answer out of turn")
        return
    state["set_profile"](None, None)
    _forget(state)
    _unstub(state)
    status = f"refused:{state['refused']}" if state["refused"] else "clean"
    status = f"tampered:{state['tampered']}" if state["tampered"] else status
    parts = attestation_text(state["rid"], state["name"], state["passables"], status, _sha256(args[0]).hexdigest())
    state.update(mode="idle", rid=None, name=None, profile=None, passables=(), live=frozenset())
    if state["gc"]:
        _gc_enable()
    _write(state["verdict_fd"], ("\t".join(parts) + "\t" + sign(state["secret"], *parts) + "\n").encode())


def _audit_hook(state):
    """The audit hook: tampering is noted the moment it happens, and the worker's sentinels move the watch on."""

    def audit(event, args):
        if state["busy"]:
            return
        if event in TAMPER_EVENTS or (event.startswith(TAMPER_PREFIXES) and event not in HARMLESS):
            _note_busy(state, event)
            return
        if event == "object.__setattr__" and len(args) == 3 and type(args[1]) is str and args[1] in GUARDED_ATTRIBUTES:
            _note_busy(state, f"a function's {args[1]} replaced")
            return
        if event not in (BEGIN, CHOSEN, END):
            return
        state["busy"] = True
        try:
            _gc_disable()
            if not _genuine(state, _getframe(1)):
                _note_tampering(state, f"{event} raised by the notebook")
            elif event == BEGIN:
                _begin(state)
            elif event == CHOSEN:
                _choose(state, args)
            else:
                _end(state, args)
        except BaseException:  # noqa: BLE001 - the hook never raises (its traceback would expose the watch)
            _note_tampering(state, "an error inside the grader's watch")
        finally:
            if state["mode"] in ("idle", RUN) and state["gc"]:
                _gc_enable()
            state["busy"] = False

    return audit


def unwire(profiles):
    """The profiles the grader sent (:func:`labkit.grading.submission.refusals.wire`) as :func:`install` takes them:
    name -> ``(names, modules, c_names)``, the refused Python code as {:func:`code_key`: readable name}, refused
    module prefixes and refused compiled ``(module, name)``."""
    return {
        name: (
            {bytes.fromhex(key): text for key, text in profile["names"].items()},
            tuple(profile["modules"]),
            frozenset(tuple(pair) for pair in profile["c_names"]),
        )
        for name, profile in profiles.items()
    }
