"""Tests of stochcable.line.mesh: node arc lengths, attachments on nodes, element properties."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stochcable.line.mesh import mesh_line
from stochcable.scene.model import Attachment, End, Line, Segment

RHO, G = 1025.0, 9.80665


def make_line(segments, attachments=()):
    total = sum(s.length for s in segments)
    return Line(
        name="l",
        end_a=End(position=(-0.8 * total, 0.0, -100.0)),
        end_b=End(position=(0.0, 0.0, -10.0)),
        segments=tuple(segments),
        attachments=tuple(attachments),
    )


SEG_A = Segment(
    length=300.0,
    ea=1e9,
    mass=100.0,
    diameter=0.1,
    cd_normal=1.1,
    cd_axial=0.1,
    ca_normal=0.9,
    elements=3,
)
SEG_B = Segment(
    length=200.0,
    ea=2e8,
    mass=20.0,
    diameter=0.2,
    cd_normal=1.3,
    cd_axial=0.2,
    ca_normal=1.1,
    elements=4,
)


def test_node_arc_lengths_uniform_per_segment():
    m = mesh_line(make_line([SEG_A, SEG_B]), RHO, G)
    expected = np.r_[np.linspace(0, 300, 4), 300 + np.linspace(0, 200, 5)[1:]]
    np.testing.assert_allclose(m.s0, expected, rtol=0, atol=1e-12)
    assert m.n_nodes == 8 and m.n_elements == 7 and m.length == 500.0
    np.testing.assert_allclose(m.l0, np.diff(expected), atol=1e-12)
    assert m.l0.sum() == pytest.approx(500.0, rel=1e-15)
    np.testing.assert_array_equal(m.segment, [0, 0, 0, 1, 1, 1, 1])
    np.testing.assert_array_equal(m.end_a, [-400.0, 0.0, -100.0])
    np.testing.assert_array_equal(m.end_b, [0.0, 0.0, -10.0])


def test_segment_properties_per_element():
    m = mesh_line(make_line([SEG_A, SEG_B]), RHO, G)
    for attr in ("ea", "mass", "diameter", "cd_normal", "cd_axial", "ca_normal"):
        np.testing.assert_array_equal(
            getattr(m, attr), [getattr(SEG_A, attr)] * 3 + [getattr(SEG_B, attr)] * 4
        )


def test_weight_is_mass_minus_displaced_times_g():
    m = mesh_line(make_line([SEG_A, SEG_B]), RHO, G)
    wa = (100.0 - RHO * math.pi * 0.1**2 / 4) * G  # DESIGN.md: w = (m - rho pi D^2/4) g
    wb = (20.0 - RHO * math.pi * 0.2**2 / 4) * G  # buoyant: 20 < 32.2 kg/m displaced
    np.testing.assert_allclose(m.weight, [wa] * 3 + [wb] * 4, rtol=1e-15)
    assert wb < 0
    # a given weight overrides the formula
    seg = SEG_A.model_copy(update={"weight": 123.0})
    assert np.all(mesh_line(make_line([seg]), RHO, G).weight == 123.0)
    # imperial units: Tuah 1982, §6.2 cable, w = (3.35 - 2.0) A g lbf/ft
    a = 0.0218
    imp = Segment(
        length=500.0, ea=8.12e6 * a, mass=3.35 * a, diameter=math.sqrt(4 * a / math.pi), elements=3
    )
    w = mesh_line(make_line([imp]), 2.0, 32.174).weight
    np.testing.assert_allclose(w, (3.35 - 2.0) * a * 32.174, rtol=1e-12)


def test_attachment_splits_element_and_sits_on_node():
    att = Attachment(at=150.0, mass=500.0, buoyancy=2000.0, added_mass=50.0, drag_area=0.3)
    m = mesh_line(make_line([SEG_A, SEG_B], [att]), RHO, G)
    # 150 m is inside element 1 (100..200 m): it is split into 100..150..200
    np.testing.assert_allclose(m.s0[:5], [0, 100, 150, 200, 300], atol=1e-12)
    assert m.n_elements == 8
    np.testing.assert_array_equal(m.segment, [0, 0, 0, 0, 1, 1, 1, 1])
    i = int(np.flatnonzero(m.node_mass)[0])
    assert m.s0[i] == 150.0
    assert (m.node_mass[i], m.node_buoyancy[i], m.node_added_mass[i], m.node_drag_area[i]) == (
        500.0,
        2000.0,
        50.0,
        0.3,
    )
    assert m.node_mass.sum() == 500.0 and m.node_buoyancy.sum() == 2000.0
    assert m.l0.sum() == pytest.approx(500.0, rel=1e-15)


def test_attachments_on_existing_nodes_and_ends_do_not_split():
    atts = [
        Attachment(at=0.0, mass=1.0),
        Attachment(at=300.0, buoyancy=900.0),
        Attachment(at=500.0, mass=2.0),
        Attachment(at=100.0 * (1 + 1e-9), mass=3.0),
    ]
    m = mesh_line(make_line([SEG_A, SEG_B], atts), RHO, G)
    assert m.n_nodes == 8  # no sliver element (snap within 1e-6 of the element length)
    assert m.node_mass[0] == 1.0 and m.node_mass[-1] == 2.0 and m.node_mass[1] == 3.0
    assert m.node_buoyancy[3] == 900.0 and m.s0[3] == 300.0


def test_two_attachments_in_one_element_and_summed_on_one_node():
    atts = [
        Attachment(at=120.0, mass=1.0),
        Attachment(at=180.0, mass=2.0),
        Attachment(at=180.0, buoyancy=5.0),
    ]
    m = mesh_line(make_line([SEG_A], atts), RHO, G)
    np.testing.assert_allclose(m.s0, [0, 100, 120, 180, 200, 300], atol=1e-12)
    assert m.node_mass[2] == 1.0 and m.node_mass[3] == 2.0 and m.node_buoyancy[3] == 5.0
