"""Example budgets for hypothesis tests whose examples are expensive (a KRL run each).

``examples(n)`` is n under the ``ci`` profile and scales with the loaded profile's
``max_examples`` otherwise (nightly: 40x), so every property test grows in ``make nightly``
and none pins a fixed count.
"""

from __future__ import annotations

from hypothesis import settings

CI_MAX_EXAMPLES = 50


def examples(ci: int) -> int:
    """The number of examples for a test that runs ``ci`` examples under the ci profile."""
    scale = settings.default.max_examples / CI_MAX_EXAMPLES
    return max(1, round(ci * scale))
