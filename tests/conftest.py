"""Suite-wide hypothesis settings.

No deadline: a test must not fail because a machine is slow (the suite has no time limits
inside tests). The example count stays at hypothesis' default of 100.
"""

from __future__ import annotations

from hypothesis import settings

settings.register_profile("collisionlab", deadline=None)
settings.load_profile("collisionlab")
