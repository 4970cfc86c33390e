"""Self-checks for the functions students write, with the lab's debugging steps.

One module per topic, plus the framework and the list of graded exercises:

* :mod:`~labkit.checks.result` - ``CheckResult``, calling student code, comparing numbers;
* :mod:`~labkit.checks.hermite` - exercises 2 to 4 (the functions);
* :mod:`~labkit.checks.drivers` - the convergence experiments: drivers, tables, rate answers;
* :mod:`~labkit.checks.plotted` - plots, judged from the lines drawn (exercises 4 and 14);
* :mod:`~labkit.checks.patches` - exercises 5 to 9;
* :mod:`~labkit.checks.splines` - exercises 10 and 12;
* :mod:`~labkit.checks.bilinear` - exercise 16 (the phi table and the functions);
* :mod:`~labkit.checks.exercises` - which checks, points and refused references each exercise has.

Notebooks use them through :mod:`labkit.check`.
"""
