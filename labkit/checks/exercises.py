"""The graded exercises: what the student defines, which checks run, points, what is switched off.

A new exercise's check goes in the topic module it belongs to (``hermite``,
``patches``, ``splines``, ``bilinear``, or a new one), and gets one entry in
:data:`EXERCISES` here. The same entry serves a student's notebook and
``labkit grade``: :func:`grade` only reads names from a mapping, which is the
notebook's own variables in the notebook and a proxy into the sandboxed
notebook in the grader (:mod:`labkit.grading.remote`).
"""
from dataclasses import dataclass

from . import bilinear, drivers, hermite, patches, plotted, splines
from .result import CheckResult

@dataclass(frozen=True)
class Refusal:
    """What a graded function may not reach while the grader calls it: whole modules, not names.

    ``modules`` are module prefixes: every Python function, method and
    compiled routine in them is switched off, private helpers included.
    ``functions`` are single functions of other modules (numpy's linear
    ``interp``). ``allowed`` are the few functions of those modules that the
    lab lets students reuse. :mod:`labkit.grading.refusals` turns this into
    what the sandbox recognises, and the source scan reads the same lists.
    """

    name: str
    modules: tuple
    functions: tuple = ()
    allowed: tuple = ()


# the lab's answers and the grader's own references: refused in every graded call that has a refusal
_GRADER = ("labkit.checks",)
INTERPOLANTS = Refusal(
    "library interpolants",
    modules=("scipy.interpolate", "scipy.ndimage", "scipy.signal._bsplines", "scipy.signal._spline",
             "scipy.signal._spline_filters", "labkit.piecewise", "labkit.splines", "labkit.monotone",
             "labkit.bilinear", "labkit.patches", "labkit.convergence", "labkit.functions") + _GRADER,
    functions=("numpy.lib._function_base_impl.interp", "numpy._core._multiarray_umath.interp",
               "numpy._core._multiarray_umath.interp_complex"),
    allowed=("labkit.piecewise.bracket",))
OWN_FUNCTIONS = Refusal("the lab's functions", modules=("labkit.functions",) + _GRADER)
OWN_PATCH = Refusal("labkit's patch", modules=("labkit.patches",) + _GRADER, allowed=("labkit.patches.Corner", "labkit.patches._vector"))
EXPERIMENTS = Refusal("labkit's experiments", modules=("labkit.convergence",) + _GRADER)


@dataclass(frozen=True)
class Part:
    """One graded piece of an exercise: a check of some of the notebook's names, and its weight.

    ``run(ns, seed)`` returns one :class:`CheckResult`, or, for parts that share
    one check (``index`` set), a list of them, run once for all. The weights of an
    exercise's parts are its points in the lab's rubric; a rubric that gives
    the exercise other points scales them (:mod:`labkit.grading.rubric`).
    """

    name: str
    weight: int
    run: object
    index: int = None  # when `run` checks several parts at once (one plot), which of its results is this part's
    refused: Refusal = None  # switched off while the grader calls the student's functions for this part
    functions: tuple = ()  # the student's functions the part calls, when not just the one named like it

    @property
    def scanned(self):
        """The student's names whose source the grader reads for refused references."""
        return self.functions or (self.name,)


@dataclass(frozen=True)
class Exercise:
    """One graded exercise.

    ``names`` are what the student's notebook defines (any of them present
    means the notebook is the exercise's own). ``parts`` are its checks with
    their weights, each with what is switched off while it calls the
    student's functions (:class:`Refusal`); anything not listed, such as
    ``labkit.bracket``, stays available. ``answers`` are the remarks and
    explanations the student writes in words: no check reads them, the
    feedback lists them for the instructor, and ``grades.csv`` has an empty
    column for each.
    """

    number: int
    names: tuple
    parts: tuple
    answers: tuple = ()  # what the student answers in words, in the order of its answer cells (the instructor reads them)

    @property
    def points(self):
        return sum(part.weight for part in self.parts)


def _driver_parts(key, driver_weight, table_weight=1, rate_weight=1):
    """The three parts of a convergence experiment: driver, table, rate answer.

    The table and the rate share one run of the student's driver at the lab's
    sizes (:func:`labkit.checks.drivers.experiment`): both are read from what
    the driver returns, so neither is earned by numbers typed in from elsewhere.
    """
    method = drivers.METHODS[key]

    def experiment(ns, seed):
        given = [ns[name] if name in ns else drivers.MISSING for name in (method.table, method.rate, method.driver)]
        return drivers.experiment(key, *given)

    return (Part(method.driver, driver_weight, lambda ns, seed: drivers.driver(key, ns[method.driver], seed),
                 refused=EXPERIMENTS),
            Part(method.table, table_weight, experiment, index=0, refused=EXPERIMENTS,
                 functions=(method.table, method.driver)),
            Part(method.rate, rate_weight, experiment, index=1, refused=EXPERIMENTS,
                 functions=(method.rate, method.driver)))


def _experiment_names(key):
    method = drivers.METHODS[key]
    return (method.driver, method.table, method.rate)


def _limacon_data(ns):
    """The notebook's own tdata, xdata, ydata, xpdata, ypdata, or None."""
    values = [ns.get(name) for name in ("tdata", "xdata", "ydata", "xpdata", "ypdata")]
    return None if any(v is None for v in values) else values


def _boiling(ns, seed):
    return plotted.boiling_plot(ns["ax14"])


EXERCISES = {e.number: e for e in (
    Exercise(2, ("eval_pherm",), (Part("eval_pherm", 10, lambda ns, seed: hermite.eval_pherm(ns["eval_pherm"], seed=seed),
                                       refused=INTERPOLANTS),)),
    Exercise(3, ("runge",) + _experiment_names("pherm"),
             (Part("runge", 3, lambda ns, seed: hermite.runge(ns["runge"], seed=seed), refused=OWN_FUNCTIONS),)
             + _driver_parts("pherm", 6, 3, 3),
             answers=("the order the table shows, against piecewise linear",)),
    Exercise(4, ("limacon_derivatives", "ax4"),
             (Part("limacon_derivatives", 8,
                   lambda ns, seed: hermite.limacon_derivatives(ns["limacon_derivatives"], seed=seed),
                   refused=OWN_FUNCTIONS),
              Part("ax4", 7, lambda ns, seed: plotted.limacon_plot(ns["ax4"], _limacon_data(ns))))),
    Exercise(5, ("coons",), (Part("coons", 12, lambda ns, seed: patches.coons(ns["coons"], seed=seed),
                                  refused=OWN_PATCH),)),
    Exercise(6, ("graded",), (Part("graded", 10, lambda ns, seed: patches.graded_corners(ns["graded"])),)),
    Exercise(7, ("straight",), (Part("straight", 10, lambda ns, seed: patches.straight_corners(ns["straight"])),),
             answers=("why these corner data give straight, evenly divided sides",)),
    Exercise(8, ("circle_sides",), (Part("circle_sides", 12, lambda ns, seed: patches.circle_corners(ns["circle_sides"])),),
             answers=("AB as parametric equations, and dx/ds, dy/ds at A and B",)),
    Exercise(9, ("two_patches", "mirror", "region"),
             (Part("two_patches", 10, lambda ns, seed: patches.two_patches(ns["two_patches"], _corners9(ns))),
              Part("region", 6, lambda ns, seed: patches.combined_mesh(ns["region"], _corners9(ns),
                                                                     ns.get("two_patches")))),
             answers=("why the mirror image's corner data make the two patches match",)),
    Exercise(10, ("ccspline", "complete_system"),
             (Part("ccspline", 15, lambda ns, seed: splines.ccspline(ns["ccspline"], ns.get("complete_system"), seed=seed),
                   refused=INTERPOLANTS, functions=("ccspline", "complete_system")),)),
    Exercise(11, _experiment_names("complete"), _driver_parts("complete", 5, 2, 2),
             answers=("the order, with f' used only at the ends",)),
    Exercise(12, ("ncspline",) + _experiment_names("natural"),
             (Part("ncspline", 9, lambda ns, seed: splines.ncspline(ns["ncspline"], seed=seed,
                                                                   system=ns.get("complete_system")),
                   refused=INTERPOLANTS),)
             + _driver_parts("natural", 2, 2, 2),
             answers=("why the natural spline's order is lower",)),
    Exercise(13, _experiment_names("notaknot"), _driver_parts("notaknot", 3, 2, 2),
             answers=("the three splines compared",)),
    Exercise(14, ("ax14",), tuple(Part(name, 2, _boiling, index=i)
                                  for i, name in enumerate(("ax14: the data", "ax14: the not-a-knot spline",
                                                            "ax14: pchip")))),
    Exercise(15, _experiment_names("pchip"), _driver_parts("pchip", 4, 2, 2),
             answers=("pchip's order against the spline's, and when to choose pchip",)),
    Exercise(16, ("phi_table", "runge2d", "eval_pbilin") + _experiment_names("bilinear"),
             (Part("phi_table", 1, lambda ns, seed: bilinear.phi_table(ns["phi_table"])),
              Part("runge2d", 1, lambda ns, seed: bilinear.runge2d(ns["runge2d"], seed=seed), refused=OWN_FUNCTIONS),
              Part("eval_pbilin", 3, lambda ns, seed: bilinear.eval_pbilin(ns["eval_pbilin"], seed=seed),
                   refused=INTERPOLANTS))
             + _driver_parts("bilinear", 1, 1, 1),
             answers=("16(a): why the phi table makes I the bilinear interpolant",
                      "the order, against piecewise linear in one dimension")),
)}
POINTS = {number: exercise.points for number, exercise in EXERCISES.items()}
ANSWERS = {f"exercise{e.number}-answer-{k}": (e.number, text)
           for e in EXERCISES.values() for k, text in enumerate(e.answers, start=1)}
REFUSALS = tuple(sorted({part.refused for e in EXERCISES.values() for part in e.parts if part.refused},
                        key=lambda refusal: refusal.name))
NAMES = {number: list(exercise.names) for number, exercise in EXERCISES.items()}


def _corners9(ns):
    return [ns["A9"], ns["B9"], ns["C9"], ns["D9"]]


def _missing(name):
    result = CheckResult(name)
    return result.fail(f"{name} is defined", "not defined when the notebook finished",
                       f"run the cell that defines {name} (and keep its name); a cell that raised stops it.")


def grade(number, namespace, seed=None):
    """Run the checks of exercise `number` on a notebook's variables; a dict for the grader.

    `namespace` is any mapping of names to the student's functions and data.
    ``defined`` says whether the notebook defines any of the exercise's names,
    so the grader can tell the exercise's own notebook from one that only
    mentions it. Each check in ``checks`` carries its part's ``weight``;
    ``fraction`` is the share of the weight that passed and ``points`` the
    weights that passed. `seed` draws the random test data afresh (see
    :func:`labkit.checks.result.case_rng`).
    """
    exercise = EXERCISES[number]
    defined = any(name in namespace for name in exercise.names)
    checks, shared = [], {}
    refusing = getattr(namespace, "refusing", None)  # the grader's proxy switches references off per part
    for part in exercise.parts:
        if refusing is not None:
            refusing(part.refused)
        try:
            if part.index is None:
                result = part.run(namespace, seed)
            else:
                if part.run not in shared:
                    shared[part.run] = part.run(namespace, seed)
                result = shared[part.run][part.index]
        except KeyError as exc:
            result = _missing(str(exc).strip("'\""))
            result.name = part.name
        except Exception as exc:  # noqa: BLE001 - a fault of the check itself costs this part, not the others
            result = CheckResult(part.name)
            result.fail("the grader could check this part", f"the check failed inside labkit ({type(exc).__name__})",
                        "this is a fault of the grader, not of your work: tell your instructor.")
        checks.append({**result.as_dict(), "name": part.name, "weight": part.weight})  # named as the student names it
    points = sum(check["weight"] for check in checks if check["passed"])
    return {"exercise": number, "passed": points == exercise.points, "points": points,
            "fraction": points / exercise.points, "defined": defined, "checks": checks}
