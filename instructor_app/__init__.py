"""The Instructor: the PySide6 desktop application."""
