"""The error of a study refused before anything runs, shared by the modules that validate it
(spec, distributions) and the command line that prints it."""


class StudyError(Exception):
    """A study refused before anything runs; the message names the place and the fix."""
