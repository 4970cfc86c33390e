"""`make lab` is the students' JupyterLab, `make lab-instructor` the instructor's.

`make lab` writes the packaged student release into a working folder (work/ unless WORK= says
otherwise) on its first run only, and opens JupyterLab there with nbgrader's lab extension and
server extensions disabled through jupyter/student/ (JUPYTER_CONFIG_PATH). `make lab-instructor`
opens notebooks/, solutions included, with nbgrader. The Makefile runs with this test's own
environment as its venv (VENV=sys.prefix, its install stamp never remade), and every folder a
test writes is a temporary one: the real work/ is never touched.
"""

import json
import os
import re
import shlex
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path

import nbformat
import pytest

from labkit.student_notebooks import paths

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted(p.name for p in (ROOT / "notebooks").glob("*.ipynb"))
STUDENT_CONFIG = ROOT / "jupyter" / "student"
VENV = Path(sys.prefix)
JUPYTER = VENV / "bin" / "jupyter"
LAB_EXTENSION = "@jupyter/nbgrader"
# JupyterLab's plugin that asks "Would you like to get notified about official Jupyter news?" over every notebook
ANNOUNCEMENTS = "@jupyterlab/apputils-extension:announcements"
TOKEN = "labkit-make-lab-test"
SECRETS = ("BEGIN SOLUTION", "END SOLUTION", "BEGIN HIDDEN TESTS")

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(shutil.which("make") is None, reason="make is not installed"),
]  # slow: make lab in a fresh folder


def _make(*args, dry=False, **env):
    """Run the Makefile in the repository with this environment as its venv."""
    command = ["make", "--no-print-directory", "-C", ROOT, "-o", VENV / ".installed", f"VENV={VENV}", *args]
    if dry:
        command.insert(1, "-n")
    return subprocess.run([str(a) for a in command], capture_output=True, text=True, timeout=120, env=_env(**env))


def _env(**extra):
    """This environment without Jupyter's folders or an outer make's flags and variables (make test runs this)."""
    outer = ("MAKEFLAGS", "MFLAGS", "MAKELEVEL", "MAKEOVERRIDES", "WORK", "ARGS")
    env = {k: v for k, v in os.environ.items() if not k.startswith("JUPYTER") and k not in outer}
    env.update(NO_COLOR="1", **extra)
    return env


def _jupyter_lab_line(target, *args, **env):
    """The (joined) `jupyter lab` command that `make -n target` prints."""
    run = _make(target, *args, dry=True, **env)
    assert run.returncode == 0, run.stderr
    text = run.stdout.replace("\\\n", " ")
    lines = [line for line in text.splitlines() if f"{JUPYTER} lab" in line]
    assert len(lines) == 1, run.stdout
    return lines[0]


def _notebook_dir(line):
    (folder,) = re.findall(r"--notebook-dir=(\S+)", line)
    return shlex.split(folder)[0]


# The commands make would run


def test_make_lab_opens_the_working_folder_with_the_student_config():
    line = _jupyter_lab_line("lab")
    assert _notebook_dir(line) == "work"
    assert "notebooks" not in line
    assert f'JUPYTER_CONFIG_PATH="{STUDENT_CONFIG}' in line


def test_make_lab_takes_another_working_folder(tmp_path):
    line = _jupyter_lab_line("lab", f"WORK={tmp_path / 'mine'}")
    assert _notebook_dir(line) == str(tmp_path / "mine")
    # only from the command line: some clusters export a WORK of their own
    assert _notebook_dir(_jupyter_lab_line("lab", WORK=str(tmp_path))) == "work"


def test_make_lab_instructor_opens_notebooks_with_nbgrader():
    line = _jupyter_lab_line("lab-instructor")
    assert _notebook_dir(line) == "notebooks"
    assert "JUPYTER_CONFIG_PATH" not in line and "student" not in line


def test_make_test_never_names_the_working_folder():
    run = _make("test", dry=True)
    assert run.returncode == 0, run.stderr
    (pytest_line,) = [line for line in run.stdout.splitlines() if " -m pytest " in line]
    assert pytest_line.split()[-1] == "notebooks"  # nbval runs the instructor notebooks, named explicitly
    assert "work" not in pytest_line.split()
    assert "/work/" in (ROOT / ".gitignore").read_text().splitlines()  # and ruff skips it with git's help


# The working folder


def test_lab_prepare_writes_the_student_release_once_and_never_overwrites_it(tmp_path):
    work = tmp_path / "work"
    first = _make("lab-prepare", f"WORK={work}")
    assert first.returncode == 0, first.stderr
    assert sorted(p.name for p in work.iterdir()) == NOTEBOOKS
    for shipped in paths():
        text = (work / shipped.name).read_text()
        assert text == shipped.read_text(), shipped.name  # the packaged release, byte for byte
        assert not [s for s in SECRETS if s in text], shipped.name
        nbformat.reads(text, as_version=4)

    edited = work / "02_convergence.ipynb"
    nb = nbformat.read(edited, as_version=4)
    nb.cells.append(nbformat.v4.new_code_cell("my_answer = 42"))
    nbformat.write(nb, edited)
    mine = edited.read_bytes()
    (work / "06_bilinear.ipynb").unlink()  # even a folder missing a notebook is the student's
    again = _make("lab-prepare", f"WORK={work}")
    assert again.returncode == 0, again.stderr
    assert "left as it is" in again.stdout
    assert edited.read_bytes() == mine
    assert sorted(p.name for p in work.iterdir()) == [n for n in NOTEBOOKS if n != "06_bilinear.ipynb"]


# nbgrader in the two sessions, asked of the real tools


def _free_port():
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def _get(base, path):
    request = urllib.request.Request(f"{base}{path}", headers={"Authorization": f"token {TOKEN}"})
    try:
        with urllib.request.urlopen(request, timeout=10) as response:
            return response.status, response.read().decode()
    except urllib.error.HTTPError as error:
        return error.code, ""


def _start(target, home, work):
    """`make target` with a JupyterLab on a free port, its Jupyter folders in `home`: (process, base URL)."""
    home.mkdir()
    env = _env(
        JUPYTER_RUNTIME_DIR=str(home / "runtime"),
        JUPYTER_DATA_DIR=str(home / "data"),
        JUPYTER_CONFIG_DIR=str(home / "config"),
        JUPYTERLAB_SETTINGS_DIR=str(home / "settings"),
        JUPYTERLAB_WORKSPACES_DIR=str(home / "workspaces"),
        IPYTHONDIR=str(home / "ipython"),
    )
    port = _free_port()
    args = (
        f"--no-browser --ip=127.0.0.1 --port={port} --ServerApp.port_retries=0 --IdentityProvider.token={TOKEN} "
        "--LabApp.check_for_updates_class=jupyterlab.NeverCheckForUpdate --LabApp.extension_manager=readonly"
    )
    command = ["make", "--no-print-directory", "-C", ROOT, "-o", VENV / ".installed", f"VENV={VENV}", target]
    command += [f"WORK={work}", f"ARGS={args}"]
    log = open(home / "server.log", "w")
    # a session of its own, so the server is stopped with make, by the id of the group started here
    process = subprocess.Popen(
        [str(a) for a in command], env=env, stdout=log, stderr=subprocess.STDOUT, start_new_session=True
    )
    return process, f"http://127.0.0.1:{port}", log


def _stop(process, log):
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGTERM)
        try:
            process.wait(timeout=20)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()
    log.close()


def _wait_until_up(process, base, home):
    deadline = time.monotonic() + 60
    while True:
        try:
            if _get(base, "/api/status")[0] == 200:
                return
        except OSError:
            pass
        if process.poll() is not None or time.monotonic() > deadline:
            raise AssertionError(f"JupyterLab did not start: {(home / 'server.log').read_text()[-3000:]}")
        time.sleep(0.25)


def _session(base):
    """What the browser is given: the page config's disabled extensions, the served files, nbgrader's pages."""
    status, page = _get(base, "/lab")
    assert status == 200
    config = json.loads(re.search(r'<script id="jupyter-config-data"[^>]*>(.*?)</script>', page, re.S).group(1))
    listing = json.loads(_get(base, "/api/contents")[1])["content"]
    return {
        "disabled": set(config.get("disabledExtensions") or ()),
        "lab extensions": {e["name"] for e in config["federated_extensions"]},
        "root": config["serverRoot"],
        "files": sorted(item["name"] for item in listing if item["name"].endswith(".ipynb")),
        "first notebook": _get(base, f"/api/contents/{NOTEBOOKS[0]}?content=1")[1],
        # formgrader (and Create Assignment's data), assignment list, course list
        "nbgrader": {path: _get(base, path)[0] for path in ("/formgrader", "/assignments", "/courses")},
    }


@pytest.fixture(scope="module")
def sessions(tmp_path_factory):
    """`make lab` (into a temporary WORK) and `make lab-instructor`, started side by side."""
    pytest.importorskip("nbgrader")
    tmp = tmp_path_factory.mktemp("make_lab")
    # jupyter labextension list, asked with the student config while the two servers start
    listing = subprocess.Popen(
        [JUPYTER, "labextension", "list"],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=_env(JUPYTER_CONFIG_PATH=str(STUDENT_CONFIG), JUPYTER_CONFIG_DIR=str(tmp / "config")),
    )
    started = {target: _start(target, tmp / target, tmp / "work") for target in ("lab", "lab-instructor")}
    try:
        seen = {}
        for target, (process, base, _) in started.items():
            _wait_until_up(process, base, tmp / target)
            seen[target] = _session(base)
            log = (tmp / target / "server.log").read_text()
            seen[target]["server extensions"] = set(re.findall(r"(\S+) \| extension was successfully loaded", log))
        output, _ = listing.communicate(timeout=120)
        seen["labextension list"] = (listing.returncode, re.sub(r"\x1b\[[0-9;]*m", "", output))
        yield seen, tmp / "work"
    finally:
        for process, _, log in started.values():
            _stop(process, log)
        if listing.poll() is None:
            listing.kill()
            listing.wait()


def test_make_lab_serves_the_student_copies_without_nbgrader(sessions):
    seen, work = sessions
    student = seen["lab"]
    assert Path(student["root"]) == work
    assert student["files"] == NOTEBOOKS
    assert not [s for s in SECRETS if s in student["first notebook"]]
    assert LAB_EXTENSION in student["lab extensions"] and LAB_EXTENSION in student["disabled"]
    assert student["nbgrader"] == dict.fromkeys(student["nbgrader"], 404), student["nbgrader"]
    # the news popup is off, and its plugin is a real one of this JupyterLab (a renamed one would pop up again)
    assert ANNOUNCEMENTS in student["disabled"] and ANNOUNCEMENTS not in seen["lab-instructor"]["disabled"]
    static = Path(sys.prefix, "share", "jupyter", "lab", "static")
    assert any(ANNOUNCEMENTS in p.read_text(errors="ignore") for p in static.glob("jlab_core*.js"))
    # every server extension nbgrader enables in the venv (the instructor's session loads them) is off here
    nbgrader = {name for name in seen["lab-instructor"]["server extensions"] if name.startswith("nbgrader.")}
    assert len(nbgrader) >= 4 and not nbgrader & student["server extensions"], student["server extensions"]


def test_make_lab_instructor_serves_notebooks_with_nbgrader(sessions):
    seen, _ = sessions
    instructor = seen["lab-instructor"]
    assert Path(instructor["root"]) == ROOT / "notebooks"
    assert instructor["files"] == NOTEBOOKS
    assert "BEGIN SOLUTION" in instructor["first notebook"]
    assert LAB_EXTENSION not in instructor["disabled"]
    assert 404 not in instructor["nbgrader"].values(), instructor["nbgrader"]
    assert {
        "nbgrader.server_extensions.formgrader",
        "nbgrader.server_extensions.assignment_list",
        "nbgrader.server_extensions.course_list",
        "nbgrader.server_extensions.validate_assignment",
    } <= instructor["server extensions"]


def test_jupyter_labextension_list_says_nbgrader_is_disabled_with_the_student_config(sessions):
    seen, _ = sessions
    status, listing = seen["labextension list"]
    assert status == 0, listing
    rows = [line.split() for line in listing.splitlines() if line.split()[:1] == [LAB_EXTENSION]]
    assert rows and rows[0][2] == "disabled", listing  # "@jupyter/nbgrader v0.9.6 disabled OK"
    assert [LAB_EXTENSION, "(all", "plugins)"] in rows, listing  # under "Disabled extensions:"
