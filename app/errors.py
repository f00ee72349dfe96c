"""Errors a user can cause (a bad scene, file or parameter): the command line prints them as one
line and exits 2; the window shows them in a dialog."""

#: longest piece of a user's value (a key, a text, a number) echoed in a message
SHOWN_CHARS = 60
#: longest path echoed in a message (its start and its end are kept)
PATH_CHARS = 160


class UserError(Exception):
    """Bad input from the user (scene, file, parameter): printed as one line, exit code 2."""


def shown(value, limit: int = SHOWN_CHARS) -> str:
    """`value` as text for a one-line message: a number rounded to 6 significant digits (an
    integer of more than 15 digits as its first digits and its length), anything else cut to
    `limit` characters with an ellipsis, line breaks shown as spaces."""
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, int):
        digits = len(str(abs(value))) if abs(value) < 10 ** 4000 else None
        if digits is None or digits > 15:
            return f"{'-' if value < 0 else ''}{str(abs(value))[:6] if digits else ''}... " \
                   f"({digits or 'over 4000'} digits)"
        return str(value)
    if isinstance(value, float):
        return f"{value:.6g}"
    text = " ".join(str(value).split("\n"))
    return text if len(text) <= limit else text[:limit - 3] + "..."


def shown_path(path) -> str:
    """A path for a one-line message: whole up to PATH_CHARS, else its start and its end."""
    text = " ".join(str(path).split("\n"))
    return text if len(text) <= PATH_CHARS else f"{text[:60]}...{text[-(PATH_CHARS - 63):]}"
