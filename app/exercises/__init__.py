"""Shape-editing exercises (Qt-free): the exercise file format, the constraints a shape must
meet, the scoring run on the numpy reference backend, grading many shapes, and the student's
attempts file. The window (app/gui/exercise_*.py) and the `feelflow exercise` command use
these; docs/reference/exercise-format.md documents the file, docs/guide/exercises.md the use.
"""
