"""The grader's own process: a class run, its engines (here or Dask), grading processes, launcher, resume."""
