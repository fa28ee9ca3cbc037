"""The behavior-tree engine of CoSTAR Instructor: pure Python, no Qt, no robot libraries."""
