"""The release gives nothing away (issue 30, item 3): no string a student can see states an answer the lab asks for.

The answers are the registry's (:meth:`labkit.exercises.registry.Registry.answer_key`: each exercise's
``withheld``, declared with it). The strings are every one the release shows: the student notebooks' markdown,
code and outputs, the outputs of the code they are given (the instructor notebooks' cells the release keeps as
they are), the figures labkit draws for them (titles, legends, labels, alternative texts, the explorers' at each
choice of their menus), the self-checks' reports on the untouched stubs and on typical wrong answers, and the docs
the release links to. Both sides are compared after :func:`labkit.exercises.answer_key.normal`.
"""

import re
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import nbformat
import numpy as np
import pytest

import labkit
from labkit import plots
from labkit._alt import figure_alt
from labkit.exercises import answer_key, experiments, patches, splines
from labkit.exercises.registry import LAB

ROOT = Path(__file__).resolve().parents[2]
RELEASE = ROOT / "labkit" / "student_notebooks"
INSTRUCTOR = ROOT / "notebooks"
KEY = [
    (number, entry, answer_key.normal(entry))
    for number, entries in LAB.answer_key().items()
    for entry in entries
    if answer_key.normal(entry)
]


def giveaways(texts):
    """'where: states exercise N's answer' for every (where, text) containing an entry of the answer key."""
    found = []
    for where, text in texts:
        plain = answer_key.normal(text)
        found += [f"{where}: states exercise {n}'s {entry!r}" for n, entry, needle in KEY if needle in plain]
    return found


def assert_clean(texts):
    found = giveaways(texts)
    assert not found, f"{len(found)} give-aways:\n" + "\n".join(found)


PICTURE_DATA = re.compile(r"data:[\w/+.-]+;base64,[A-Za-z0-9+/=\s]*")


def _joined(value):
    return "".join(value) if isinstance(value, list) else str(value)


def output_texts(where, outputs):
    """The texts of a cell's outputs: streams, text/plain and text/html, errors, and every image's metadata."""
    for k, output in enumerate(outputs):
        if "text" in output:
            yield f"{where}, output {k}", _joined(output["text"])
        for kind, value in output.get("data", {}).items():
            if kind.startswith("text/") or kind.endswith("json"):  # a picture inside (an <img>'s data) is no text
                yield f"{where}, output {k} ({kind})", PICTURE_DATA.sub("data:", _joined(value))
        for kind, value in output.get("metadata", {}).items():
            yield f"{where}, output {k} metadata {kind}", str(value)
        if output.get("output_type") == "error":
            yield f"{where}, output {k} (error)", f"{output.get('ename')}: {output.get('evalue')}"


def release_texts():
    """Every cell of the student release: its source and its outputs."""
    for path in sorted(RELEASE.glob("*.ipynb")):
        for i, cell in enumerate(nbformat.read(path, as_version=4).cells):
            where = f"{path.name} cell {i} ({cell.cell_type})"
            yield where, cell.source
            yield from output_texts(where, cell.get("outputs", ()))


def given_outputs():
    """What the release's given code prints and draws: the outputs of the instructor notebooks' cells that the
    release keeps unchanged (its solution cells are the student's own work, and not shown)."""
    for path in sorted(RELEASE.glob("*.ipynb")):
        kept = {cell.source for cell in nbformat.read(path, as_version=4).cells if cell.cell_type == "code"}
        for i, cell in enumerate(nbformat.read(INSTRUCTOR / path.name, as_version=4).cells):
            if cell.cell_type == "code" and cell.source in kept:
                yield from output_texts(f"{path.name} cell {i} as run", cell.get("outputs", ()))


def figure_texts(figure, where):
    """The words of a matplotlib figure: titles, axis labels, legends, texts and its alternative text."""
    yield f"{where} (alt text)", figure_alt(figure)
    if figure._suptitle is not None:
        yield f"{where} (title)", figure._suptitle.get_text()
    for ax in figure.axes:
        for loc in ("left", "center", "right"):
            yield f"{where} (title)", ax.get_title(loc)
        yield f"{where} (axis labels)", f"{ax.get_xlabel()} | {ax.get_ylabel()}"
        legend = ax.get_legend()
        if legend is not None:
            yield f"{where} (legend)", " | ".join(text.get_text() for text in legend.get_texts())
        yield f"{where} (line labels)", " | ".join(str(line.get_label()) for line in ax.get_lines())
        yield f"{where} (texts)", " | ".join(text.get_text() for text in ax.texts)


def drawn(where, draw):
    plt.close("all")
    draw()
    texts = [text for number in plt.get_fignums() for text in figure_texts(plt.figure(number), where)]
    plt.close("all")
    return texts


def scene_texts(widget, where):
    """What the browser draws and reads of a live picture: the texts of its scene (titles, tick labels) and
    its description (the alt text)."""
    items = widget.scene.get("items", [])
    yield f"{where} (drawn texts)", " | ".join(item["text"] for item in items if item["kind"] == "text")
    yield f"{where} (alt text shown)", getattr(widget, "description", "") or getattr(widget, "alt", "")


def explorer_texts(name, explorer):
    """An explorer's figure, and the live picture the browser draws of it, at its first state and at every
    choice of each menu and box."""
    import ipywidgets as widgets

    texts = list(figure_texts(explorer.figure, f"{name}()")) + list(scene_texts(explorer.image, f"{name}()"))
    for control_name, control in explorer.controls.items():
        start = control.value
        if isinstance(control, widgets.Dropdown):
            choices = [value for _, value in control.options] if isinstance(control.options[0], tuple) else []
        elif isinstance(control, widgets.Checkbox):
            choices = [not start]
        else:
            choices = [control.min, control.max]
        for choice in choices or control.options:
            control.value = choice
            texts += figure_texts(explorer.figure, f"{name}() with {control_name} = {choice!r}")
            texts += scene_texts(explorer.image, f"{name}() with {control_name} = {choice!r}")
        control.value = start
    return texts


def labkit_figures():
    """The figures of labkit.plots the notebooks draw, as they draw them, and the explorers."""
    texts = []
    tables = [labkit.convergence_table(m) for m in ("plin", "pherm", "complete", "natural", "notaknot", "pchip")]
    texts += drawn("plots.plot_convergence(every method)", lambda: plots.plot_convergence(tables))
    for method in ("plin", "pherm"):
        texts += drawn(f"plots.plot_limacon({method})", lambda m=method: plots.plot_limacon(20, method=m))
    texts += drawn("plots.plot_second_derivatives(7)", lambda: plots.plot_second_derivatives(7))
    for method in ("plin", "pherm", "complete", "natural", "notaknot", "pchip"):
        texts += drawn(
            f"plots.plot_interpolation_error({method})", lambda m=method: plots.plot_interpolation_error([m], 11)
        )
    boiling = (np.arange(5.0), np.array([0.0, 1.0, 2.0, 2.0, 2.0]))
    texts += drawn("plots.plot_spline_vs_pchip", lambda: plots.plot_spline_vs_pchip(*boiling))
    texts += drawn("plots.plot_bilinear_error(11)", lambda: plots.plot_bilinear_error(11, ntest=61))
    for name in ("limacon_explorer", "convergence_explorer", "mesh_explorer", "spline_explorer", "pchip_explorer"):
        texts += explorer_texts(name, getattr(plots, name)())
    texts += explorer_texts("bilinear_explorer", plots.bilinear_explorer())
    editor = plots.patch_editor()  # the corner data it opens on, as its readout shows them, and its figure
    texts += [("plots.patch_editor() readout", editor.widget_.readout)]
    texts += figure_texts(editor.figure, "plots.patch_editor()")
    texts += scene_texts(editor.widget_, "plots.patch_editor()")
    plt.close("all")
    return texts


# -- self-checks on the stubs and on typical wrong answers ------------------------------------------------------------


def stub(*args, **kwargs):
    raise NotImplementedError()


def pherm_driver(ndata, f=labkit.runge, interpolate=labkit.eval_pherm, absolute=False):
    xdata = np.linspace(0, 5, ndata)
    ydata, ypdata = f(xdata)
    xtest = np.linspace(0, 5, 4001)
    exact = f(xtest)[0]
    error = np.max(np.abs(np.asarray(interpolate(xdata, ydata, ypdata, xtest)) - exact))
    return error if absolute else error / np.max(np.abs(exact))


def mirrored_with(mirror, order):
    """two_patches meshing ABCD, and abcd from the corners `order` of ABCD mirrored by `mirror`."""

    def two_patches(A, B, C, D):
        by_label = dict(zip("ABCD", (A, B, C, D)))
        first = labkit.quad_mesh(*labkit.patch(A, B, C, D, np.linspace(0, 1, 20), np.linspace(0, 1, 30)))
        second = labkit.patch(*(mirror(by_label[k]) for k in order), np.linspace(0, 1, 30), np.linspace(0, 1, 20))
        return first, labkit.quad_mesh(*second)

    return two_patches


R2 = np.sqrt(2) / 2
CORNERS9 = {
    "A9": labkit.Corner([0, 1], [np.pi / 4, 0], [0, 1]),
    "B9": labkit.Corner([R2, R2], [R2 * np.pi / 4, -R2 * np.pi / 4], [2 - R2, 2 - R2]),
    "C9": labkit.Corner([2, 2], [2, 0], [2 - R2, 2 - R2]),
    "D9": labkit.Corner([0, 2], [2, 0], [0, 1]),
}


def wrong_answers():
    """(what, exercise, namespace): typical slips, written with labkit's own pieces."""
    ndata = experiments.convergence.DEFAULT_NDATA
    table = [pherm_driver(n) for n in ndata]
    yield "runge's derivative with the wrong sign", 3, {"runge": experiments.runge_sign_slip}
    yield "runge's derivative without the square", 3, {"runge": experiments.runge_unsquared}
    yield "an absolute error", 3, {"test_pherm_interpolate": lambda n, f, i: pherm_driver(n, f, i, absolute=True)}
    yield "a driver ignoring f", 3, {"test_pherm_interpolate": lambda n, f=None, i=None: pherm_driver(n)}
    for rate in (2, 3, 8, 16, 4.5, "four"):
        yield f"rate {rate!r}", 3, {"test_pherm_interpolate": pherm_driver, "errors_pherm": table, "rate_pherm": rate}
    off = list(table)
    off[3] *= 1.3
    yield "a table entry off", 3, {"test_pherm_interpolate": pherm_driver, "errors_pherm": off, "rate_pherm": 4}
    yield "a table typed in short", 3, {"test_pherm_interpolate": pherm_driver, "errors_pherm": table[:-1]}

    def no_product_rule(t, r0=1.15):
        return -(r0 + np.cos(t)) * np.sin(t), (r0 + np.cos(t)) * np.cos(t)

    def wrong_sign(t, r0=1.15):
        r = r0 + np.cos(t)
        return np.sin(t) * np.cos(t) - r * np.sin(t), np.sin(t) ** 2 + r * np.cos(t)

    yield "limaçon derivatives without the product rule", 4, {"limacon_derivatives": no_product_rule}
    yield "limaçon derivatives with dr/dt's sign wrong", 4, {"limacon_derivatives": wrong_sign}
    yield "coons with s and t swapped", 5, {"coons": lambda A, B, C, D, s, t: labkit.patch(A, B, C, D, t, s)}
    chord = [
        labkit.Corner([-1, 0], [1, 0], [0, 1], [-1, -0.5]),
        labkit.Corner([1, 0], [1, 0], [0, 1], [-1, -0.5]),
        labkit.Corner([1, 0.5], [1, 0], [0, 1], [-1, -0.5]),
        labkit.Corner([0, 1], [1, 0], [0, 1], [-1, -0.5]),
    ]
    yield "straight sides with the unit square's derivatives", 7, {"straight": chord}
    square = [labkit.Corner(p, [1, 0], [0, 1]) for p in ([0, 0], [1, 0], [1, 1], [0, 1])]
    yield "quarter circles with the chords' derivatives", 8, {"circle_sides": square}
    for k, (_, mirror, order, _counts) in enumerate(patches.MIRROR_SLIPS):
        yield f"mirror slip {k + 1}", 9, {"two_patches": mirrored_with(mirror, order), **CORNERS9}

    def complete_rows(x, y):
        return splines._natural_slopes(np.asarray(x, float), np.asarray(y, float), rows_in_a=False, rows_in_d=False)

    def rows_in_a_only(x, y):
        return splines._natural_slopes(np.asarray(x, float), np.asarray(y, float), rows_in_d=False)

    yield "the natural spline with the complete spline's end rows", 12, {"ncspline": complete_rows}
    yield "the natural spline's end rows in A only", 12, {"ncspline": rows_in_a_only}
    yield "the phi table transposed the wrong way", 16, {"phi_table": np.ones((4, 4))}
    yield "the phi table of the unit square's corners", 16, {"phi_table": np.zeros((4, 4))}


# "got ..." echoes the student's own value back: a table the student filled in is the student's, not a give-away
OWN = re.compile(r"got \[[^\]]*\]|got [^,;:]*")


def result_texts(where, value):
    """Every string in what LAB.check returns (step names, details, hints), the student's own values left out."""
    if isinstance(value, str):
        yield where, OWN.sub("got (yours)", value)
    elif isinstance(value, dict):
        for item in value.values():
            yield from result_texts(where, item)
    elif isinstance(value, (list, tuple)):
        for item in value:
            yield from result_texts(where, item)


def check_texts():
    texts = []
    for number, exercise in LAB.exercises.items():
        texts += result_texts(f"exercise {number}'s checks with nothing defined", LAB.check(number, {}))
        stubs = {name: stub for name in exercise.names}
        texts += result_texts(f"exercise {number}'s checks on the stubs", LAB.check(number, stubs))
    for what, number, namespace in wrong_answers():
        texts += result_texts(f"exercise {number}'s checks on {what}", LAB.check(number, namespace))
    return texts


STUDENT_DOCS = ("docs/students.md", "docs/library.md")  # what the README points students to


def linked_docs():
    """The students' docs, and the files of this repository the release's markdown links to."""
    found = [(f"{name} (the students' docs)", (ROOT / name).read_text(encoding="utf-8")) for name in STUDENT_DOCS]
    for where, text in release_texts():
        for target in re.findall(r"\]\(([^)#\s]+)", text) + re.findall(r"\bdocs/[\w./-]+\.md\b", text):
            if target.startswith(("http:", "https:")):
                target = target.split("/labkit/blob/main/")[-1] if "/labkit/blob/main/" in target else ""
            path = (ROOT / target) if target else None
            if path is not None and path.is_file():
                found.append((f"{target} (linked from {where})", path.read_text()))
    return found


# -- the tests ------------------------------------------------------------------------------------------------------


def test_the_answer_key_lists_each_asked_for_answer_computed_from_labkit():
    key = LAB.answer_key()
    for experiment in LAB.experiments.values():
        number = next(
            n for n, e in LAB.exercises.items() if any(getattr(p, "experiment", None) is experiment for p in e.parts)
        )
        assert f"order {experiment.order}" in key[number] and f"O(h^{experiment.order})" in key[number]
        assert experiment.order == experiment.observed_order  # the key's order is what labkit's table shows
        # each error of labkit's table, as labkit.ratio_table prints it, is in the key
        printed = labkit.ratio_table("t", list(experiment.ndata), experiment.reference(experiment.ndata))
        first = f"{experiment.reference(experiment.ndata)[1]:.3e}"
        assert first in printed and first in key[number]
    # the key's Runge derivative (its Python spelling) is the derivative of 1/(1+x^2): a centred difference
    x, h = np.linspace(-2, 2, 9), 1e-6
    python = next(entry for entry in key[3] if "**" in entry)
    difference = (1 / (1 + (x + h) ** 2) - 1 / (1 + (x - h) ** 2)) / (2 * h)
    np.testing.assert_allclose(eval(python, {"x": x}), difference, atol=1e-8)
    assert {"d is B", "1 on the diagonal, 0 elsewhere", "-sin^2 t + r cos t"} <= {e for v in key.values() for e in v}


def test_normal_reads_the_spellings_of_one_formula_alike():
    spellings = ["-2*x/(1 + x**2)**2", "\u22122x/(1+x^2)^2", "- 2 x / (1 + x^2)^2", "-2*x / (1+x**2) ** 2"]
    assert len({answer_key.normal(text) for text in spellings}) == 1
    assert answer_key.normal("O(h^4)") in answer_key.normal("the error is O(h**4) here")
    with pytest.raises(ValueError, match="whole number of at least 1"):
        answer_key.orders(0)


def test_the_scan_finds_a_planted_give_away():
    cells = list(release_texts())
    assert cells, "the release has no notebooks to scan"
    where, text = cells[0]
    planted = [(where, text + "\n\nThe Hermite table shows order 4, as expected.")]
    assert any("order 4" in found for found in giveaways(planted))
    assert giveaways([("hint", "yprime = -2*x/(1 + x**2)**2")])
    assert giveaways([("legend", "Natural Cubic Spline (second-order)")])
    value = LAB.experiment("natural").reference([21])[0]
    assert giveaways([("printout", f"Err(21) = {value:.4e}")])
    assert not giveaways([("hint", "the rate is the exponent p of the power of two 2**p the ratios settle near")])


def test_the_scan_finds_the_answers_in_the_solutions_the_release_strips():
    for path in sorted(INSTRUCTOR.glob("*.ipynb")):
        cells = nbformat.read(path, as_version=4).cells
        solutions = [
            (f"{path.name} cell {i}", c.source) for i, c in enumerate(cells) if "### BEGIN SOLUTION" in c.source
        ]
        assert giveaways(solutions), f"{path.name}'s solutions state none of the answer key"
    runge = next(
        c.source
        for c in nbformat.read(INSTRUCTOR / "02_convergence.ipynb", as_version=4).cells
        if "def runge" in c.source
    )
    assert any("exercise 3's" in found for found in giveaways([("the solution of 3(a)", runge)]))


def test_the_release_notebooks_give_nothing_away():
    assert_clean(release_texts())


def test_the_given_code_prints_and_draws_nothing_that_gives_an_answer_away():
    assert_clean(given_outputs())


def test_labkits_figures_and_explorers_name_methods_never_their_orders():
    texts = labkit_figures()
    legends = " ".join(text for where, text in texts if "(legend)" in where)
    assert "Natural Cubic Spline" in legends  # the methods keep their names
    drawn_live = " ".join(text for where, text in texts if "(drawn texts)" in where)
    assert "Interpolation error, 81 equally spaced points" in drawn_live  # the scan reads what the browser draws
    assert "worst quality" in drawn_live and "Bilinear error, 41 x 41 data" in drawn_live
    assert_clean(texts)


def test_the_self_checks_give_nothing_away_on_stubs_and_wrong_answers():
    texts = check_texts()
    hints = [text for where, text in texts if "wrong sign" in where or "mirror slip" in where]
    assert hints  # the wrong answers did reach the checks
    assert_clean(texts)


def test_the_docs_the_release_links_to_give_nothing_away():
    assert_clean(linked_docs())
