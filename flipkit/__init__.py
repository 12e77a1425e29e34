"""flipkit: fast joint-space direct collocation for nonprehensile manipulation.

Reproduces Kolathaya et al., "Direct Collocation for Dynamic Behaviors with Nonprehensile
Contacts: Application to Flipping Burgers" (RA-L 2018) and goes beyond it.
"""

__version__ = "0.1.0"

from flipkit.config import CellConfig  # noqa: E402
from flipkit.errors import FlipkitError  # noqa: E402

__all__ = ["CellConfig", "FlipkitError", "__version__"]
