"""The student's own figure on the feedback page (issue 45): a plot part that failed shows the lines the grader
read from the student's plot, drawn from numbers only, bounded, with y upwards; a part not done or passed shows
none."""

from types import SimpleNamespace

import numpy as np
import pytest

from labkit.exercises.registry import _student_figure
from labkit.grading.store import feedback
from labkit.grading.store.report import SubmissionGrade
from labkit.grading.store.rubric import default
from labkit.plotdata import Line, figure_data


def grade_with(check):
    checks = [check, {"name": "limacon_derivatives", "weight": 8, "passed": True, "hint": "", "steps": []}]
    verdict = {"fraction": 8 / 15 if not check["passed"] else 1.0, "passed": check["passed"], "checks": checks}
    return SubmissionGrade("ada", {4: verdict}, [], seed=1, rubric=default())


def plot_check(figure, passed=False, kind=None):
    step = {"step": "the curve is the Hermite interpolant", "passed": passed, "detail": "" if passed else "off"}
    return {"name": "ax4", "weight": 7, "passed": passed, "hint": "plot xherm, yherm.",
            "steps": [{**step, **({"kind": kind} if kind else {})}], "figure": figure}  # fmt: skip


def page_of(check):
    return feedback.html(feedback.build(grade_with(check)))


def test_a_failed_plot_shows_the_students_lines_scaled_into_the_box_with_y_upwards():
    line = figure_data([Line(np.linspace(0.0, 1.0, 11), np.linspace(0.0, 1.0, 11), "None", "-")])
    page = page_of(plot_check(line))
    assert page.count("<svg") == 1 and 'role="img"' in page and "Your plot ax4" in page
    points = page.split('<polyline points="')[1].split('"')[0].split()
    width, height, margin = feedback.FIGURE_BOX
    assert points[0] == f"{margin:.1f},{height - margin:.1f}"  # (0, 0) at the bottom left
    assert points[-1] == f"{width - margin:.1f},{margin:.1f}"  # (1, 1) at the top right
    assert len(points) == 11


def test_markers_without_a_line_are_drawn_as_points():
    dots = figure_data([Line(np.arange(5.0), np.arange(5.0) ** 2, "o", "None")])
    page = page_of(plot_check(dots))
    assert page.count("<circle") == 5 and "<polyline" not in page


def test_a_plot_not_done_or_passed_shows_no_figure():
    line = figure_data([Line(np.arange(3.0), np.arange(3.0), "None", "-")])
    assert "<svg" not in page_of(plot_check(line, kind="not done"))
    assert "<svg" not in page_of(plot_check(line, passed=True))


def test_what_a_result_file_holds_is_bounded_and_only_numbers_are_drawn():
    long = {"x": list(range(10_000)), "y": list(range(10_000)), "joined": True}
    page = page_of(plot_check([long] * 20))
    assert page.count("<polyline") == 8 and max(len(p.split('"')[1].split()) for p in page.split("points=")[1:]) <= 300
    hostile = [{"x": ["<script>", 1], "y": [1, 2]}, {"x": [float("nan"), 1.0], "y": [0.0, 1.0]}, "<b>", None]
    assert "<svg" not in page_of(plot_check(hostile)) and "<script>" not in page_of(plot_check(hostile))


def test_figure_data_keeps_at_most_its_points_and_both_ends():
    line = Line(np.linspace(0.0, 1.0, 5001), np.sin(np.linspace(0.0, 1.0, 5001)), "None", "-")
    (shown,) = figure_data([line], max_points=300)
    assert len(shown["x"]) <= 301 and shown["x"][0] == 0.0 and shown["x"][-1] == 1.0
    np.testing.assert_allclose(shown["y"], np.sin(shown["x"]), rtol=1e-5, atol=1e-6)
    assert figure_data([Line(np.array([np.nan]), np.array([1.0]), "o", "None")]) == []


def test_the_grader_attaches_the_plot_a_failed_part_read_and_nothing_else():
    part = SimpleNamespace(reads=("tval", "ax4"))
    lines = [Line(np.arange(4.0), np.arange(4.0) * 2, "None", "-")]
    namespace = {"tval": np.arange(4.0), "ax4": lines}
    failed = plot_check(None)
    assert _student_figure(part, namespace, failed) == {"figure": figure_data(lines)}
    assert _student_figure(part, namespace, plot_check(None, passed=True)) == {}
    assert _student_figure(part, namespace, plot_check(None, kind="not done")) == {}
    assert _student_figure(SimpleNamespace(reads=("tval",)), namespace, failed) == {}


@pytest.mark.slow  # grades a notebook in the sandbox
def test_a_graded_plot_slip_shows_the_students_curve_on_the_feedback_page(tmp_path):
    from catalog import MISTAKES, plant
    from conftest import sandbox_or_skip
    from small_class import SEED, cli

    sandbox_or_skip()
    slip = next(entry for entry in MISTAKES if entry.name == "limacon_drawn_exactly")
    plant(slip, tmp_path / "subs" / "ada")
    done = cli("grade", tmp_path / "subs", "--out", tmp_path / "out", "--seed", SEED, "--jobs", "1", timeout=600)
    assert done.returncode in (0, 1), done.stderr
    page = (tmp_path / "out" / "feedback" / "ada.html").read_text(encoding="utf-8")
    assert page.count("<svg") == 1 and "Your plot ax4" in page
    points = page.split('<polyline points="')[1].split('"')[0].split()
    assert len(points) >= 100  # the student's whole curve (211 points or more, thinned), not the data points
