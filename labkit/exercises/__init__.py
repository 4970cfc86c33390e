"""The lab's exercises: what each one is, and the checks of the students' work.

One module per topic declares its exercises (:class:`~labkit.exercises.model.Exercise`)
next to the checks they use:

* :mod:`~labkit.exercises.hermite` - exercises 2 to 4;
* :mod:`~labkit.exercises.patches` - exercises 5 to 9;
* :mod:`~labkit.exercises.splines` - exercises 10 to 13;
* :mod:`~labkit.exercises.monotone` - exercises 14 and 15;
* :mod:`~labkit.exercises.bilinear` - exercise 16.

The framework they share:

* :mod:`~labkit.exercises.model` - ``Exercise``, ``Part``, ``Refusal``: what a declaration is made of;
* :mod:`~labkit.exercises.result` - ``CheckResult``, calling student code, student values as floats;
* :mod:`~labkit.exercises.experiments` - the convergence experiments: drivers, tables, rate answers;
* :mod:`~labkit.exercises.plotted` - plots, judged from the lines drawn;
* :mod:`~labkit.exercises.registry` - the exercises gathered, and everything derived from them.

Students call the checks through :mod:`labkit.check`; ``labkit grade`` runs them
from outside the notebook (:mod:`labkit.grading`).
"""
