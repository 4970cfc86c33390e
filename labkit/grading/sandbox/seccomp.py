"""The system calls a sandboxed notebook may not make: small classic-BPF seccomp filters, written out here.

The sandbox's filter (:func:`pipe_with_program`) refuses memory an address-space limit does not count
(``memfd_create``, ``memfd_secret``), keyrings, which outlive the sandbox and are shared per uid (``add_key``,
``request_key``, ``keyctl``), another process's memory (``ptrace``, ``process_vm_readv``/``writev``), and new
threads, which the watch would not follow (``clone`` with ``CLONE_THREAD``; ``clone3``, whose flags a filter cannot
read, gets "not implemented" so libc falls back to ``clone``). The notebook's process adds ``rt_sigaction``
(:func:`install_for_notebook`), whatever the backend. Calls of another architecture are refused too.
"""

import errno
import os
import platform
import struct

# the refused calls' numbers on the architectures the grader runs on
_TABLE = """
name               x86_64  aarch64
memfd_create       319     279
memfd_secret       447     447
add_key            248     217
request_key        249     218
keyctl             250     219
ptrace             101     117
process_vm_readv   310     270
process_vm_writev  311     271
clone              56      220
clone3             435     435
rt_sigaction       13      134
"""
_ROWS = [line.split() for line in _TABLE.strip().splitlines()]
SYSCALLS = {machine: {row[0]: int(row[column]) for row in _ROWS[1:]} for column, machine in enumerate(_ROWS[0][1:], 1)}
SANDBOX = tuple(row[0] for row in _ROWS[1:9])  # all but clone, clone3 and rt_sigaction
AUDIT_ARCH = {"x86_64": 0xC000003E, "aarch64": 0xC00000B7}
X32_BIT = 0x40000000  # x86_64's x32 calls: the same functions under numbers with this bit
CLONE_THREAD = 0x00010000

_LD_W_ABS, _JEQ_K, _JGE_K, _JSET_K, _RET_K = 0x20, 0x15, 0x35, 0x45, 0x06
_ALLOW, _ERRNO = 0x7FFF0000, 0x00050000
_NR, _ARCH, _ARG0 = 0, 4, 16  # offsets in struct seccomp_data (the low word of args[0] on little-endian)


def _instruction(code, jt, jf, k):
    return struct.pack("=HBBI", code, jt, jf, k)


def program(machine=None, deny=SANDBOX):
    """A filter as bytes (struct sock_filter[]), or None on an unknown architecture: `deny` get EPERM, as ``clone``
    with ``CLONE_THREAD`` does, and ``clone3`` ENOSYS."""
    machine = machine or platform.machine()
    if machine not in SYSCALLS:
        return None
    numbers = SYSCALLS[machine]
    # (code, jump if true, jump if false, k), the jumps naming a target: "deny", "nosys", "allow" or a count
    body = [(_LD_W_ABS, 0, 0, _ARCH), (_JEQ_K, 0, "deny", AUDIT_ARCH[machine]), (_LD_W_ABS, 0, 0, _NR)]
    if machine == "x86_64":
        body.append((_JGE_K, "deny", 0, X32_BIT))
    body += [(_JEQ_K, "deny", 0, numbers[name]) for name in deny]
    # threads last: the flags check leaves the accumulator holding the flags, not the number
    body += [
        (_JEQ_K, "nosys", 0, numbers["clone3"]),
        (_JEQ_K, 0, 2, numbers["clone"]),
        (_LD_W_ABS, 0, 0, _ARG0),
        (_JSET_K, "deny", 0, CLONE_THREAD),
    ]
    body += [(_RET_K, 0, 0, _ALLOW), (_RET_K, 0, 0, _ERRNO | errno.EPERM), (_RET_K, 0, 0, _ERRNO | errno.ENOSYS)]
    targets = {"allow": len(body) - 3, "deny": len(body) - 2, "nosys": len(body) - 1}

    def jump(index, to):
        return to if isinstance(to, int) else targets[to] - index - 1

    return b"".join(_instruction(op, jump(i, jt), jump(i, jf), k) for i, (op, jt, jf, k) in enumerate(body))


def pipe_with_program():
    """A readable descriptor holding the sandbox's filter (for a sandbox that loads it from one), or None."""
    code = program()
    if code is None:
        return None
    read, write = os.pipe()
    os.write(write, code)  # far below a pipe's buffer
    os.close(write)
    return read


def install_for_notebook():
    """From now on, the sandbox's refusals and ``rt_sigaction`` here (True), or False where that cannot be done.
    The notebook's process calls it after its timer's handler is set and before any student code runs."""
    code = program(deny=SANDBOX + ("rt_sigaction",))
    if code is None:
        return False
    import ctypes

    class Program(ctypes.Structure):
        _fields_ = [("len", ctypes.c_ushort), ("filter", ctypes.c_char_p)]

    libc = ctypes.CDLL(None, use_errno=True)
    if libc.prctl(38, 1, 0, 0, 0) != 0:  # PR_SET_NO_NEW_PRIVS, needed to install a filter unprivileged
        return False
    filters = ctypes.create_string_buffer(code, len(code))
    prog = Program(len(code) // 8, ctypes.cast(filters, ctypes.c_char_p))
    return libc.prctl(22, 2, ctypes.byref(prog), 0, 0) == 0  # PR_SET_SECCOMP, SECCOMP_MODE_FILTER
