"""One slider move through a real Jupyter server, with labkit's server extension and without it.

Run: ``.venv/bin/python benchmarks/bench_websocket.py [--moves 15]``. It starts JupyterLab twice (the harness
of the browser test, ``tests/browser/jupyterlab_session.py``): once as this environment configures it
(``labkit.server_extension`` on: the kernel websocket without Nagle's delay) and once with the extension
switched off on the command line. In each it starts a kernel, builds the pchip explorer there, and, as a
websocket client in Python (no browser), sets the slider ``--moves`` times, timing each move from the comm
message sent to the kernel's answer (the new scene) received, and to the kernel's "idle".

It prints the median and the largest time of each, and how many moves took longer than 30 ms. Nothing is
asserted: the figures are in docs/performance.md.
"""

import argparse
import asyncio
import json
import statistics
import sys
import tempfile
import time
import uuid
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "browser"))
from jupyterlab_session import jupyterlab, kernel_channels

SETUP = "from labkit import plots\nexplorer = plots.pchip_explorer()\nprint(explorer.controls['y1'].model_id)"
SLOW_MS = 30


def _message(kind, content):
    header = {"msg_id": uuid.uuid4().hex, "msg_type": kind, "username": "", "session": "bench", "version": "5.3"}
    return {"header": header, "parent_header": {}, "metadata": {}, "content": content, "channel": "shell"}


async def _moves(base, count):
    from tornado.websocket import websocket_connect

    socket = await websocket_connect(kernel_channels(base))
    run = _message("execute_request", {"code": SETUP, "silent": False})
    await socket.write_message(json.dumps(run))
    model = None
    while True:
        reply = await asyncio.wait_for(socket.read_message(), 120)
        if isinstance(reply, bytes):
            continue
        reply = json.loads(reply)
        if reply["msg_type"] == "stream":
            model = reply["content"]["text"].split()[-1]
        if reply["msg_type"] == "error":
            raise RuntimeError(f"the explorer was not built: {reply['content']['evalue']}")
        state = reply["content"].get("execution_state")
        if state == "idle" and reply["parent_header"].get("msg_id") == run["header"]["msg_id"]:
            break
    answers, idles = [], []
    for k in range(count):
        state = {"method": "update", "state": {"value": 1.05 + 0.05 * k}}
        move = _message("comm_msg", {"comm_id": model, "data": state})
        start = time.perf_counter()
        await socket.write_message(json.dumps(move))
        answered = None
        while True:
            reply = await asyncio.wait_for(socket.read_message(), 30)
            if isinstance(reply, bytes):  # the scene's buffers come as a binary frame after its message
                answered = answered or time.perf_counter()
                continue
            reply = json.loads(reply)
            if reply["parent_header"].get("msg_id") != move["header"]["msg_id"]:
                continue
            if reply["content"].get("execution_state") == "idle":
                idles.append(1000 * (time.perf_counter() - start))
                break
        answers.append(1000 * ((answered or time.perf_counter()) - start))
        await asyncio.sleep(0.1)
    socket.close()
    return answers, idles


def measure(extension_on, count):
    options = () if extension_on else ('--ServerApp.jpserver_extensions={"labkit.server_extension": False}',)
    with tempfile.TemporaryDirectory() as home:
        served = Path(home) / "served"
        served.mkdir()
        with jupyterlab(home, served, *options) as base:
            answers, idles = asyncio.run(_moves(base, count))
        log = (Path(home) / "server.log").read_text()
    loaded = "labkit: kernel websockets send without Nagle's delay" in log
    if loaded != extension_on:
        which = "did not load" if extension_on else "loaded"
        raise RuntimeError(f"labkit's server extension {which}: see {log[-500:]}")
    return answers, idles


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--moves", type=int, default=15)
    args = parser.parse_args()
    columns = f"{'to the scene: median':>22}{'largest':>9}{'to idle: median':>17}{'largest':>9}{'> 30 ms':>9}"
    print(f"{'server':<34}{columns}")
    for extension_on in (True, False):
        answers, idles = measure(extension_on, args.moves)
        name = "labkit's extension (Nagle off)" if extension_on else "extension off (Nagle on)"
        slow = sum(t > SLOW_MS for t in answers)
        print(
            f"{name:<34}{statistics.median(answers):19.1f} ms{max(answers):6.0f} ms"
            f"{statistics.median(idles):14.1f} ms{max(idles):6.0f} ms{slow:6d}/{len(answers)}",
            flush=True,
        )


if __name__ == "__main__":
    main()
