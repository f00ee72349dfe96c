"""Exercise files (package data): shape-editing design tasks, format in
docs/reference/exercise-format.md, their shapes in shapes/."""
