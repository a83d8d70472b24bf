"""The public face documents itself: every function and class ``texsynth`` exports, and every
registered method's function, has the numpydoc sections Parameters (when it takes any
argument), Returns (functions only), References and Examples (with a line to run), and its
Parameters name every argument of its signature. Every method's module, and each exported module
that implements a paper, has a References section too.

Sections are found by their underlined headers (numpydoc: the name, then a line of dashes as
long); a parameter entry is a line at the section's own indent, ``name : type`` or
``a, b : type`` (so ``rng, progress`` or ``width, height`` may share one entry).
"""

import inspect
import re

import pytest

import texsynth

REQUIRED = ("Parameters", "Returns", "References", "Examples")


def sections(doc: str) -> dict[str, list[str]]:
    """{header: its lines} of a numpydoc docstring (``inspect.cleandoc``-ed)."""
    lines = inspect.cleandoc(doc or "").splitlines()
    found, current = {}, None
    for i, line in enumerate(lines):
        following = lines[i + 1] if i + 1 < len(lines) else ""
        if line.strip() and re.fullmatch(r"-{3,}", following.strip()) and \
                len(following.strip()) == len(line.strip()):
            current = line.strip()
            found[current] = []
        elif current is not None and not re.fullmatch(r"-{3,}", line.strip()):
            found[current].append(line)
    return found


def documented_parameters(lines: list[str]) -> set[str]:
    """The names of the entries of a Parameters section: ``a, b : type`` lines, not indented."""
    names = set()
    for line in lines:
        if line.strip() and not line[0].isspace():
            names.update(n.strip().lstrip("*") for n in line.split(" : ")[0].split(","))
    return names


def signature_parameters(obj) -> list[str]:
    try:
        signature = inspect.signature(obj)
    except ValueError:  # an exception class: no signature of its own (BaseException's *args)
        return []
    return [p.name for p in signature.parameters.values() if p.name not in ("self", "cls")]


def _public():
    for name in texsynth.__all__:
        obj = getattr(texsynth, name)
        if inspect.isfunction(obj) or inspect.isclass(obj):
            yield f"texsynth.{name}", obj
    for method in texsynth.methods():
        yield f"method {method.name}", method.function


PUBLIC = dict(_public())


def missing(obj) -> list[str]:
    """What the docstring of ``obj`` lacks: a section, or a parameter its Parameters omit."""
    found = sections(obj.__doc__)
    arguments = signature_parameters(obj)
    required = [s for s in REQUIRED if not (s == "Returns" and inspect.isclass(obj))
                and not (s == "Parameters" and not arguments and not inspect.isclass(obj))]
    lacking = [s for s in required if s not in found]
    if "Examples" in found and not any(">>>" in line for line in found["Examples"]):
        lacking.append("Examples (no >>> line to run)")
    if "Parameters" in found:
        documented = documented_parameters(found["Parameters"])
        lacking += [f"parameter {p!r}" for p in arguments if p not in documented]
    return lacking


@pytest.mark.parametrize("name", sorted(PUBLIC))
def test_documented(name):
    assert not missing(PUBLIC[name]), f"{name} lacks: {', '.join(missing(PUBLIC[name]))}"


def test_a_lost_section_fails():
    def documented(a, b, rng, progress):
        """One line.

        Parameters
        ----------
        a, b : int
        rng, progress
            Together.

        Returns
        -------
        int

        References
        ----------
        Nobody 2000, 1.

        Examples
        --------
        >>> 1
        1
        """

    assert missing(documented) == []
    doc = documented.__doc__
    for header in REQUIRED:
        documented.__doc__ = doc.replace(header, "Notes", 1)
        assert missing(documented), header
    documented.__doc__ = doc.replace("a, b : int", "a : int")
    assert missing(documented) == ["parameter 'b'"]


def test_every_method_module_cites_its_papers():
    modules = {inspect.getmodule(m.function) for m in texsynth.methods()} | {texsynth.segmentation}
    lacking = [m.__name__ for m in modules if "References" not in sections(m.__doc__)]
    assert not lacking, f"no References section in the docstring of {', '.join(sorted(lacking))}"
