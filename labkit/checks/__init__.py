"""Self-checks for the functions students write, with the lab's debugging steps.

One module per topic, plus the framework and the list of graded exercises:

* :mod:`~labkit.checks.result` - ``CheckResult``, calling student code, comparing numbers;
* :mod:`~labkit.checks.hermite` - exercises 2 and 3;
* :mod:`~labkit.checks.patches` - exercises 5 to 9;
* :mod:`~labkit.checks.splines` - exercises 10 and 12;
* :mod:`~labkit.checks.bilinear` - exercise 16;
* :mod:`~labkit.checks.exercises` - which checks, points and refused references each exercise has.

Notebooks use them through :mod:`labkit.check`.
"""
