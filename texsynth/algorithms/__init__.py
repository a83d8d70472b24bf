# ruff: noqa: I001  (registration order is panel order: composite last)
"""One home per method: importing this package registers them all, in panel order.

Each method is a module, or a package when it has helpers of its own, holding its registration
(``METHOD = register(Method(...))``), its paper's algorithm and its docstring. Building blocks
that several methods share are in ``texsynth.blocks``.

The folder is ``algorithms``, not ``methods``, because ``texsynth.methods`` is the public
function that lists them; a subpackage of that name would replace it on import.
"""

from . import heeger_bergen  # noqa: F401
from . import efros_leung  # noqa: F401
from . import multiscale_mrf  # noqa: F401
from . import de_bonet  # noqa: F401
from . import cooccurrence  # noqa: F401
from . import texture_optimization  # noqa: F401
from . import composite  # noqa: F401  (its fill choices list the methods before it)
# Methods added later come after: Blender saves the method enum of a scene by its index.
from . import portilla_simoncelli  # noqa: F401
from . import random_phase  # noqa: F401
