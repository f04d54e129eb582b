"""Every row of the public unit table (fogdrift.export.conversions.UNIT_TABLE) against a value worked out by hand.

Issue 36: 17 of its 44 rows were checked, so a wrong factor in any other row shipped.  Each row here is written
again from the units' definitions (1 deg = pi/180 rad, 1 h = 3600 s, 1/sqrt(Hz) = sqrt(s), g = 9.80665 m/s^2,
1 Gal = 1 cm/s^2, 1 arcsec = 1/3600 deg), never from the table's own constants, and the table holds exactly these
rows: one added without a hand value here fails too.
"""

from __future__ import annotations

import math

import pytest

from fogdrift.export.conversions import SI_UNITS, UNIT_TABLE, from_si, quantity_of_unit, to_si

RAD_PER_DEG = math.pi / 180.0
G = 9.80665                     # standard gravity, m/s^2 (CGPM 1901)
SQRT_H = 60.0                   # sqrt(3600 s)

#: (term, unit) -> (quantity, SI value of one unit), by hand.
HAND = {
    # gyro, N (angle random walk) -> rad/s/sqrt(Hz) = rad/sqrt(s)
    ("N", "deg/sqrt(h)"): ("gyro", RAD_PER_DEG / SQRT_H),            # 1 deg/sqrt(3600 s)
    ("N", "rad/s/sqrt(Hz)"): ("gyro", 1.0),
    ("N", "rad/sqrt(s)"): ("gyro", 1.0),                              # rad/s * sqrt(s) = rad/sqrt(s)
    ("N", "deg/s/sqrt(Hz)"): ("gyro", RAD_PER_DEG),
    ("N", "deg/h/sqrt(Hz)"): ("gyro", RAD_PER_DEG / 3600.0),          # (deg/3600 s) * sqrt(s)
    ("N", "deg/h*sqrt(s)"): ("gyro", RAD_PER_DEG / 3600.0),
    # gyro, K (rate random walk) -> rad/s^2/sqrt(Hz) = rad/s^1.5
    ("K", "deg/h^1.5"): ("gyro", RAD_PER_DEG / 3600.0 ** 1.5),        # 3600^1.5 = 216 000
    ("K", "deg/h/sqrt(h)"): ("gyro", RAD_PER_DEG / (3600.0 * SQRT_H)),
    ("K", "rad/s^2/sqrt(Hz)"): ("gyro", 1.0),
    ("K", "rad/s^1.5"): ("gyro", 1.0),
    # gyro, B (a rate) -> rad/s
    ("B", "deg/h"): ("gyro", RAD_PER_DEG / 3600.0),
    ("B", "deg/s"): ("gyro", RAD_PER_DEG),
    ("B", "rad/s"): ("gyro", 1.0),
    # gyro, Q (angle quantization) -> rad
    ("Q", "urad"): ("gyro", 1e-6),
    ("Q", "arcsec"): ("gyro", RAD_PER_DEG / 3600.0),
    ("Q", "rad"): ("gyro", 1.0),
    # gyro, R (rate ramp) -> rad/s^2
    ("R", "deg/h^2"): ("gyro", RAD_PER_DEG / (3600.0 * 3600.0)),
    ("R", "rad/s^2"): ("gyro", 1.0),
    # gyro, q_c (Markov driving density, IEEE-952 C.6) -> rad/s/sqrt(s)
    ("q_c", "deg/h/sqrt(s)"): ("gyro", RAD_PER_DEG / 3600.0),
    # accelerometer, N (velocity random walk) -> m/s^2/sqrt(Hz) = m/s/sqrt(s)
    ("N", "m/s/sqrt(h)"): ("accel", 1.0 / SQRT_H),
    ("N", "m/s^2/sqrt(Hz)"): ("accel", 1.0),
    ("N", "m/s/sqrt(s)"): ("accel", 1.0),
    ("N", "m/s^2*sqrt(s)"): ("accel", 1.0),
    ("N", "ug/sqrt(Hz)"): ("accel", G / 1e6),
    ("N", "mg/sqrt(Hz)"): ("accel", G / 1e3),
    # accelerometer, K (acceleration random walk) -> m/s^3/sqrt(Hz) = m/s^2.5
    ("K", "m/s^3/sqrt(Hz)"): ("accel", 1.0),
    ("K", "m/s^2/sqrt(s)"): ("accel", 1.0),
    ("K", "m/s^2.5"): ("accel", 1.0),
    ("K", "m/s^2/sqrt(h)"): ("accel", 1.0 / SQRT_H),
    ("K", "m/s/h^1.5"): ("accel", 1.0 / 3600.0 ** 1.5),
    ("K", "m/s/h/sqrt(h)"): ("accel", 1.0 / (3600.0 * SQRT_H)),
    ("K", "ug/sqrt(s)"): ("accel", G / 1e6),                          # ug/sqrt(s) = 9.80665e-6 m/s^2/sqrt(s)
    # accelerometer, B (a specific force) -> m/s^2
    ("B", "m/s^2"): ("accel", 1.0),
    ("B", "ug"): ("accel", G / 1e6),
    ("B", "mg"): ("accel", G / 1e3),
    ("B", "g"): ("accel", G),
    ("B", "mGal"): ("accel", 1e-3 * 1e-2),                            # 1 mGal = 1e-3 cm/s^2
    ("B", "m/s/h"): ("accel", 1.0 / 3600.0),
    # accelerometer, Q (velocity quantization) -> m/s
    ("Q", "m/s"): ("accel", 1.0),
    ("Q", "mm/s"): ("accel", 1e-3),
    # accelerometer, R (ramp) -> m/s^3
    ("R", "m/s^3"): ("accel", 1.0),
    ("R", "m/s^2/h"): ("accel", 1.0 / 3600.0),
    ("R", "m/s/h^2"): ("accel", 1.0 / (3600.0 * 3600.0)),
    # accelerometer, q_c -> m/s^2/sqrt(s)
    ("q_c", "m/s^2/sqrt(s)"): ("accel", 1.0),
}


def test_the_table_holds_exactly_the_rows_worked_out_here():
    assert len(UNIT_TABLE) == 44
    assert sorted(UNIT_TABLE) == sorted(HAND)


@pytest.mark.parametrize("key", sorted(HAND), ids=lambda k: f"{k[0]}[{k[1]}]")
def test_every_row_against_its_hand_value(key):
    term, unit = key
    quantity, factor = HAND[key]
    assert UNIT_TABLE[key][0] == quantity
    assert UNIT_TABLE[key][1] == pytest.approx(factor, rel=1e-12)
    # through the public functions too: 2.5 of the unit, its SI unit, and back
    v, si_unit, _ = to_si(2.5, term, unit)
    assert v == pytest.approx(2.5 * factor, rel=1e-12)
    assert si_unit == SI_UNITS[(quantity, term)]
    assert from_si(v, term, unit) == pytest.approx(2.5, rel=1e-12)
    assert quantity_of_unit(term, unit) == quantity


def test_a_few_rows_against_published_figures():
    # independent of the derivations above: figures as datasheets and IEEE Std 952 / 1293 print them
    assert to_si(1.0, "N", "deg/sqrt(h)")[0] == pytest.approx(2.908882e-4, rel=1e-6)   # rad/sqrt(s)
    assert to_si(1.0, "Q", "arcsec")[0] == pytest.approx(4.848137e-6, rel=1e-6)        # rad
    assert to_si(1.0, "B", "deg/h")[0] == pytest.approx(4.848137e-6, rel=1e-6)         # rad/s (earth rate 15 deg/h)
    assert to_si(1.0, "B", "mGal")[0] == pytest.approx(1e-5, rel=1e-12)                # m/s^2
    assert to_si(1.0, "K", "deg/h^1.5")[0] == pytest.approx(8.080228e-8, rel=1e-6)     # rad/s^1.5
