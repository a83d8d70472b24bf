"""Version requirements read from a wheel's METADATA, without ``packaging`` or ``bpy``.

Shared by dependencies.py (the extension's check that the numpy it meets is one the bundled
scipy supports) and addon_build.py (the builds' and tests' checks of the same).
"""

import re


def requirement(metadata: str, package: str) -> str | None:
    """The version comparisons (``'<2.5,>=1.23.5'``) with which a wheel's METADATA text requires
    ``package`` (unconditionally: not for an extra), or None when it does not.

    Examples
    --------
    >>> requirement("Requires-Dist: numpy<2.5,>=1.23.5", "numpy")
    '<2.5,>=1.23.5'
    """
    found = [match[1] for line in metadata.splitlines()
             if (match := re.fullmatch(rf"Requires-Dist: {re.escape(package)}\s*([^;a-z]*)",
                                       line, flags=re.IGNORECASE))]
    if len(found) > 1:
        raise LookupError(f"{len(found)} unconditional requirements of {package}")
    return found[0].strip() if found else None


def satisfies(version: str, comparisons: str) -> bool:
    """Whether ``version`` meets every ``<``, ``<=``, ``>``, ``>=`` of ``comparisons``; releases
    compare as numbers (2.10 > 2.9, 2.5 == 2.5.0), a pre-release or local part is dropped.

    Examples
    --------
    >>> satisfies("2.5.5", "<2.5,>=1.23.5"), satisfies("2.3.4", "<2.5,>=1.23.5")
    (False, True)
    """
    def release(text: str) -> tuple[int, ...]:
        numbers = [int(n) for n in re.match(r"\d+(?:\.\d+)*", text)[0].split(".")]
        return tuple(numbers + [0] * (4 - len(numbers)))

    bounds = re.findall(r"([<>]=?)\s*(\d[\w.]*)", comparisons)
    if not bounds:
        raise ValueError(f"no comparisons in {comparisons!r}")
    order = {"<": tuple.__lt__, "<=": tuple.__le__, ">": tuple.__gt__, ">=": tuple.__ge__}
    return all(order[op](release(version), release(bound)) for op, bound in bounds)
