"""The fork server: workers forked from one warm process, each as isolated from the others as a sandbox of its own.

The hostile class (tests/grading/test_hostile.py) and the catalog's identical-grades
test (tests/exercises/test_catalog.py) go through the fork server, since a grading run
uses it by default; here two notebooks forked from one server at the same
time try to reach each other, and the plain way is checked to give the same
grades.
"""

import csv
import json
import os
import shutil

import pytest
from catalog import MISTAKES, plant
from conftest import sandbox_or_skip

from labkit.grading import grade
from labkit.grading.options import GradeOptions
from labkit.grading.sandbox import backends, forkserver, remote
from labkit.grading.sandbox.backends.base import Limits

NOTEBOOKS = os.path.join(
    os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))), "notebooks"
)

WALK = """
import os, socket, stat
def writable_folders():
    found = []
    for top, folders, _ in os.walk("/"):
        if top.startswith(("/proc", "/sys")):
            folders[:] = []
            continue
        if os.access(top, os.W_OK):
            found.append(top)
    return found
"""

FIRST = (
    WALK
    + """
left = []
for folder in writable_folders():
    try:
        with open(os.path.join(folder, "left-by-first"), "w") as handle:
            handle.write("first")
        left.append(folder)
    except OSError:
        pass
listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
listener.bind("\\0labkit-first")
listener.listen(1)
terminal, other_end = os.openpty()  # a terminal anyone may open, if anyone else could see it
os.chmod(os.ttyname(other_end), 0o666)
uid, pids = os.getuid(), sorted(int(p) for p in os.listdir("/proc") if p.isdigit())
"""
)

SECOND = (
    WALK
    + """
sockets = 0
for fd in os.listdir("/proc/self/fd"):
    try:
        sockets += stat.S_ISSOCK(os.fstat(int(fd)).st_mode)
    except OSError:
        pass
found = [f for f in writable_folders() if os.path.exists(os.path.join(f, "left-by-first"))]
try:
    probe = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    probe.connect("\\0labkit-first")
    reached = 1
except OSError:
    reached = 0
uid, pids = os.getuid(), sorted(int(p) for p in os.listdir("/proc") if p.isdigit())
terminals = [name for name in os.listdir("/dev/pts") if name != "ptmx"]
try:
    open("/proc/1/environ", "rb").read()  # the supervisor's: readable only if its memory were
    peeked = 1
except OSError:
    peeked = 0
status = dict(line.split(":", 1) for line in open("/proc/self/status").read().splitlines() if ":" in line)
capabilities = int(status["CapEff"].strip(), 16)
no_new_privileges = int(status["NoNewPrivs"].strip())
"""
)


@pytest.fixture(scope="module")
def server():
    sandbox_or_skip()
    backend = backends.get_backend("bwrap")
    if backend.zygote_box(["true"], Limits(), ()) is None:
        pytest.skip("the bwrap backend offers a fork server only to a grader running as root")
    with forkserver.ForkServer(backend, Limits()) as started:
        yield started


def _run(notebook, cells):
    answer = notebook.request({"op": "run", "cells": cells, "cell_timeout": 120}, 150)
    assert answer.get("errors") == [], answer
    return remote.Namespace(notebook)


@pytest.mark.slow  # starts a sandbox
def test_two_notebooks_from_one_server_share_no_file_socket_process_or_descriptor(server):
    with remote.NotebookHandle(GradeOptions()) as first, remote.NotebookHandle(GradeOptions()) as second:
        assert isinstance(first.box, forkserver.ForkedBox) and isinstance(second.box, forkserver.ForkedBox)
        ours = _run(first, [FIRST])
        left = ours["left"]
        assert "/tmp" in left and "/home/student" in left  # it could write, and did, in its own folders
        theirs = _run(second, [SECOND])
        assert theirs["found"] == [], "a file the first notebook wrote is visible to the second"
        assert theirs["reached"] == 0, "the second notebook reached the first one's socket"
        assert ours["uid"] != theirs["uid"] and 0 not in (ours["uid"], theirs["uid"])
        # each sees only its own processes, numbered from 1 in a namespace of its own
        assert min(ours["pids"]) == 1 and min(theirs["pids"]) == 1 and len(theirs["pids"]) <= 3
        assert theirs["sockets"] == 0, "the student's process holds a socket: the fork server's was not closed"
        assert theirs["capabilities"] == 0 and theirs["no_new_privileges"] == 1
        assert theirs["terminals"] == [], "the second notebook sees the first one's terminal"
        assert theirs["peeked"] == 0, "the notebook could read its supervisor's memory"


@pytest.mark.slow  # starts a sandbox
def test_a_notebook_after_another_finds_nothing_it_left(server):
    with remote.NotebookHandle(GradeOptions()) as first:
        assert _run(first, [FIRST])["left"]
    with remote.NotebookHandle(GradeOptions()) as second:
        assert _run(second, [SECOND])["found"] == []


@pytest.mark.slow  # starts a sandbox
def test_the_notebooks_limits_hold_in_a_forked_worker(server):
    options = GradeOptions(limits=Limits(memory=600 * 1024**2))
    with remote.NotebookHandle(options) as notebook:
        assert isinstance(notebook.box, forkserver.ForkedBox)
        ns = _run(
            notebook,
            [
                "import resource\nlimit = resource.getrlimit(resource.RLIMIT_AS)[0]\n"
                "try:\n    block = bytearray(900 * 1024**2)\n    held = 1\nexcept MemoryError:\n    held = 0"
            ],
        )
        assert ns["limit"] == 600 * 1024**2 and ns["held"] == 0


@pytest.mark.slow  # starts a sandbox
def test_without_a_server_or_with_a_dead_one_a_notebook_gets_a_sandbox_of_its_own():
    sandbox_or_skip()
    backend = backends.get_backend("bwrap")
    if backend.zygote_box(["true"], Limits(), ()) is None:
        pytest.skip("no fork server here")
    with remote.NotebookHandle(GradeOptions(fork_server=False)) as plain:
        assert not isinstance(plain.box, forkserver.ForkedBox)
    started = forkserver.ForkServer(backend, Limits()).start()
    try:
        started.box.stop()  # the server dies; its socket is still held here
        with remote.NotebookHandle(GradeOptions()) as notebook:
            assert not isinstance(notebook.box, forkserver.ForkedBox)
            assert _run(notebook, ["x = 6 * 7"])["x"] == 42
    finally:
        started.stop()
    assert forkserver.client() is None or forkserver.client()[0] is not started.socket  # no longer asked


def _rows(path):
    with open(path, newline="", encoding="utf-8") as handle:
        return list(csv.reader(handle))


@pytest.mark.slow  # starts a sandbox
def test_the_plain_way_and_the_fork_server_give_the_same_grades(tmp_path):
    sandbox_or_skip()
    solved = tmp_path / "solved"
    solved.mkdir()
    shutil.copy(os.path.join(NOTEBOOKS, "06_bilinear.ipynb"), solved)
    entry = next(m for m in MISTAKES if m.notebook == "06_bilinear.ipynb")  # a typical mistake in exercise 16
    slip = plant(entry, tmp_path / "slip").parent
    runs = {}
    for label, fork in (("forked", True), ("plain", False)):
        grade([solved, slip], tmp_path / label, GradeOptions(fork_server=fork, seed=5), progress=False)
        runs[label] = json.loads((tmp_path / label / "run.json").read_text())
    assert runs["plain"]["fork server"] is False and runs["plain"]["forked grading processes"] is False
    if os.geteuid() == 0:
        assert runs["forked"]["fork server"] is True and runs["forked"]["forked grading processes"] is True
    assert _rows(tmp_path / "forked" / "grades.csv") == _rows(tmp_path / "plain" / "grades.csv")
    totals = {row[0]: row for row in _rows(tmp_path / "plain" / "grades.csv")[1:]}
    assert totals["solved"] != totals["slip"]


DESCRIPTORS = """
import os
held = []
for fd in os.listdir("/proc/self/fd"):
    try:
        held.append(os.readlink(f"/proc/self/fd/{fd}").split(":")[0])
    except OSError:  # the listing's own descriptor, closed by now
        pass
held.sort()
"""


@pytest.mark.slow  # starts a sandbox
def test_a_forked_notebook_holds_no_descriptor_a_sandbox_of_its_own_would_not(server):
    """Only the notebook's own pipes cross the fork: not the keeper's control or status pipes, nor the files
    that put it in its cgroup, nor the server's socket."""
    held = {}
    for label, fork in (("forked", True), ("plain", False)):
        with remote.NotebookHandle(GradeOptions(fork_server=fork)) as notebook:
            assert isinstance(notebook.box, forkserver.ForkedBox) == fork
            held[label] = _run(notebook, [DESCRIPTORS])["held"]
    assert held["forked"] == held["plain"]
