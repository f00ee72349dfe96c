"""Errors a user can cause (a bad scene, file or parameter): the command line prints them as one
line and exits 2; the window shows them in a dialog."""


class UserError(Exception):
    """Bad input from the user (scene, file, parameter): printed as one line, exit code 2."""
