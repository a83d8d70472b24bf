"""One module per algorithm; importing this package registers them all, in panel order.

The folder is `algorithms`, not `methods`, because `texsynth.methods` is the public function
that lists them; a subpackage of that name would replace it on import.
"""

from . import heeger_bergen  # noqa: F401
