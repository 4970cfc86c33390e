"""The system calls a sandboxed notebook may not make: a small seccomp filter for bwrap's ``--seccomp``.

Refused, with ``EPERM``, whatever the notebook's process tries them for:

* ``memfd_create`` and ``memfd_secret``: anonymous files hold memory that
  an address-space limit does not count;
* ``add_key``, ``request_key`` and ``keyctl``: the kernel's keyrings outlive
  the sandbox and are shared by every process of one uid, so one
  submission could leave a key for the next one to read;
* ``ptrace``, ``process_vm_readv`` and ``process_vm_writev``: no process of
  the sandbox reads or writes another's memory (the grading watch lives in
  the supervisor, :mod:`labkit.grading.worker`).

System calls of another architecture (32-bit calls on a 64-bit machine)
are refused too: they would reach the same functions under other numbers.
The filter is classic BPF, written out here because it is a dozen
instructions; bwrap installs it just before it starts the worker.
"""
import os
import platform
import struct

# numbers of the refused calls on the architectures the grader runs on
SYSCALLS = {
    "x86_64": {"memfd_create": 319, "memfd_secret": 447, "add_key": 248, "request_key": 249, "keyctl": 250,
               "ptrace": 101, "process_vm_readv": 310, "process_vm_writev": 311},
    "aarch64": {"memfd_create": 279, "memfd_secret": 447, "add_key": 217, "request_key": 218, "keyctl": 219,
                "ptrace": 117, "process_vm_readv": 270, "process_vm_writev": 271},
}
AUDIT_ARCH = {"x86_64": 0xC000003E, "aarch64": 0xC00000B7}
X32_BIT = 0x40000000  # x86_64's x32 calls: the same functions under numbers with this bit

_LD_W_ABS, _JEQ_K, _JGE_K, _RET_K = 0x20, 0x15, 0x35, 0x06
_ALLOW, _ERRNO = 0x7FFF0000, 0x00050000
_EPERM = 1


def _instruction(code, jt, jf, k):
    return struct.pack("=HBBI", code, jt, jf, k)


def program(machine=None):
    """The filter as bytes (struct sock_filter[]), or None on an architecture it does not know."""
    machine = machine or platform.machine()
    if machine not in SYSCALLS:
        return None
    numbers = sorted(set(SYSCALLS[machine].values()))
    deny = _ERRNO | _EPERM
    body = [_instruction(_LD_W_ABS, 0, 0, 4)]  # the architecture of the call
    # not ours: jump to the last instruction (deny)
    tail = len(numbers) + (3 if machine == "x86_64" else 2)
    body.append(_instruction(_JEQ_K, 0, tail, AUDIT_ARCH[machine]))
    body.append(_instruction(_LD_W_ABS, 0, 0, 0))  # the call's number
    if machine == "x86_64":
        body.append(_instruction(_JGE_K, len(numbers) + 1, 0, X32_BIT))
    for index, number in enumerate(numbers):
        body.append(_instruction(_JEQ_K, len(numbers) - index, 0, number))
    body.append(_instruction(_RET_K, 0, 0, _ALLOW))
    body.append(_instruction(_RET_K, 0, 0, deny))
    return b"".join(body)


def pipe_with_program():
    """A readable descriptor holding the filter (for ``bwrap --seccomp FD``), or None."""
    code = program()
    if code is None:
        return None
    read, write = os.pipe()
    os.write(write, code)  # far below a pipe's buffer
    os.close(write)
    return read
