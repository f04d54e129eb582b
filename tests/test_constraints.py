"""The rules of declared settings (fogdrift.constraints), against hand-picked values at and beside their bounds."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fogdrift import constraints as C
from fogdrift.errors import ConfigError


def test_rules_at_and_beside_their_bounds():
    one = C.Integer(1)
    assert one.holds(1) and one.holds(np.int64(7)) and one.holds(10**12)
    assert not any(one.holds(v) for v in (0, -3, True, 1.5, "2", None, np.float64(2.0)))
    open_ = C.Number(0.0, 1.0)
    assert open_.holds(0.5) and open_.holds(np.float32(0.25)) and open_.holds(1e-12)
    assert not any(open_.holds(v) for v in (0.0, 1.0, -0.1, math.nan, math.inf, False, "0.5", None))
    left = C.Number(0.0, 1.0, "left")
    assert left.holds(0.0) and not left.holds(1.0)
    above = C.Number(0.0)
    assert above.holds(1e9) and not above.holds(0.0) and not above.holds(math.inf)
    assert C.Number(0.0, 1.0, "both").describe() == "a number in [0, 1]" and above.describe() == "a number > 0"
    choice = C.Choice(("bptt", "bp"))
    assert choice.holds("bp") and not choice.holds("BP") and not choice.holds(None)
    with pytest.raises(ConfigError) as info:
        one.check("lags", 0)
    msg = info.value.args[0]  # by its meaning: the option, the rule's bound, the value given
    assert msg.startswith("{opt:lags} ") and "integer >= 1" in msg and msg.endswith("got 0")
