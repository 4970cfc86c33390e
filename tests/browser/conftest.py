import sys


def pytest_terminal_summary(terminalreporter):
    """Show the axe-core check's findings per notebook in every run's summary, not only with -s: what is in
    the notebooks' outputs (asserted to be nothing serious) and what JupyterLab itself causes (named only)."""
    found = getattr(sys.modules.get("test_accessibility"), "AXE", {})
    if not found:
        return
    terminalreporter.section("axe-core in JupyterLab: serious and critical violations")
    for notebook, result in found.items():
        nodes = ", ".join(f"{impact} {n}" for impact, n in result["all"].items() if n) or "none"
        terminalreporter.write_line(f"{notebook}: nodes by impact: {nodes}")
        for where in ("outputs", "jupyterlab"):
            rules = sorted({f"{rule} ({impact})" for rule, impact, *_ in result[where]})
            label = "in labkit's outputs" if where == "outputs" else "JupyterLab's own"
            terminalreporter.write_line(f"    {label:<20} {', '.join(rules) or 'none'}")
