"""Developer tools of the repository; not part of the installed application (pyproject.toml's
package discovery leaves this folder out).
"""
