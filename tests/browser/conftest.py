"""Print the browser test's slider latencies in the summary of every run (not only with -s)."""
import sys


def pytest_terminal_summary(terminalreporter):
    module = sys.modules.get("test_jupyterlab")
    latencies = getattr(module, "LATENCIES", {})
    if latencies:
        terminalreporter.section("slider move -> new plot in JupyterLab (median of 4 moves)")
        for name, ms in latencies.items():
            terminalreporter.write_line(f"{name:<24}{ms:6.0f} ms")
