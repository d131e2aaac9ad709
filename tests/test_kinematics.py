"""Geometry: the paper's equations, Jacobians, the inverse geometric model, the leg swap."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import biped
from biped.model.kinematics import QP2, XH, ZH, swap_legs
from tests.conftest import random_state

ROBOT = biped.Robot.paper()


def paper_points(robot, knee, q):
    """Hip, swing heel and swing toe from eqs. (1)-(12), stance ankle at (0, h_p)."""
    qp1, qp2, q1, q2, q3, q4, q5, _, _ = np.moveaxis(q, -1, 0)
    r1, r2 = (robot.r1, robot.r2) if knee == "rolling" else (0.0, 0.0)
    l1, l2 = robot.shank_length - r1, robot.thigh_length - r2
    link = r1 + r2
    g1 = (r1 * q1 + r2 * q2) / link if link else 0.0 * q1
    g2 = (r1 * q4 + r2 * q3) / link if link else 0.0 * q1
    lp, Lp, hp = robot.foot_heel, robot.foot_length, robot.ankle_height
    xh = -l2 * np.sin(q2) - link * np.sin(g1) - l1 * np.sin(q1)  # (1), (7)
    zh = l2 * np.cos(q2) + link * np.cos(g1) + l1 * np.cos(q1) + hp  # (2), (8)
    x_ankle = xh + l2 * np.sin(q3) + link * np.sin(g2) + l1 * np.sin(q4)
    z_ankle = zh - l2 * np.cos(q3) - link * np.cos(g2) - l1 * np.cos(q4)
    # (3)-(6), (9)-(12) without the spurious "+ h_p" of the printed z equations: heights here
    # are measured from the ground, so a flat foot on the ground has its heel at z = 0.
    heel = (
        x_ankle - lp * np.cos(qp2) + hp * np.sin(qp2),
        z_ankle - lp * np.sin(qp2) - hp * np.cos(qp2),
    )
    toe = (
        x_ankle - (lp - Lp) * np.cos(qp2) + hp * np.sin(qp2),
        z_ankle - (lp - Lp) * np.sin(qp2) - hp * np.cos(qp2),
    )
    return np.stack([xh, zh], -1), np.stack(heel, -1), np.stack(toe, -1)


def test_points_follow_the_paper_equations(model):
    """Hip, swing heel and swing toe agree with eqs. (1)-(12) for random postures."""
    q, _, _ = random_state(model, seed=1)
    hip, heel, toe = paper_points(model.robot, model.knee, q)
    np.testing.assert_allclose(q[:, [XH, ZH]], hip, atol=1e-12)
    np.testing.assert_allclose(model.point(q, "swing_heel"), heel, atol=1e-12)
    np.testing.assert_allclose(model.point(q, "swing_toe"), toe, atol=1e-12)
    np.testing.assert_allclose(
        model.point(q, "stance_heel"), [[-ROBOT.foot_heel, 0.0]] * len(q), atol=1e-12
    )
    np.testing.assert_allclose(
        model.point(q, "stance_toe"),
        [[ROBOT.foot_length - ROBOT.foot_heel, 0.0]] * len(q),
        atol=1e-12,
    )


def test_rolling_knee_circles_touch(model):
    """The centres C1, C2 are r1 + r2 apart and the contact point lies between them."""
    q, _, _ = random_state(model, seed=2)
    r1, r2 = model.radii
    for side in ("stance", "swing"):
        c2 = model.point(q, f"{side}_knee_thigh")
        c1 = model.point(q, f"{side}_knee_shank")
        contact = model.point(q, f"{side}_knee")
        np.testing.assert_allclose(np.linalg.norm(c1 - c2, axis=-1), r1 + r2, atol=1e-12)
        np.testing.assert_allclose(np.linalg.norm(contact - c2, axis=-1), r2, atol=1e-12)
        np.testing.assert_allclose(np.linalg.norm(contact - c1, axis=-1), r1, atol=1e-12)


def test_rolling_without_slip(model):
    """The thigh and shank points at the rolling contact have the same velocity."""
    if model.knee == "revolute":
        pytest.skip("no rolling contact")
    q, qd, _ = random_state(model, seed=3)
    r1, r2 = model.radii
    h = 1e-30
    qc = q + 1j * h * qd
    c2, c1, contact = (
        model.point(qc, n) for n in ("stance_knee_thigh", "stance_knee_shank", "stance_knee")
    )
    # Material points of the thigh and the shank that coincide with the contact point now.
    dir_thigh = (contact.real - c2.real) / r2
    dir_shank = (contact.real - c1.real) / r1
    perp = np.stack([-1.0, 1.0]) * 1.0
    v_thigh = c2.imag / h + qd[:, [3]] * r2 * perp * dir_thigh[:, ::-1]
    v_shank = c1.imag / h + qd[:, [2]] * r1 * perp * dir_shank[:, ::-1]
    np.testing.assert_allclose(v_thigh, v_shank, atol=1e-10)


@pytest.mark.parametrize("name", ["swing_toe", "swing_heel", "stance_ankle", "head", "swing_knee"])
def test_point_jacobian_matches_finite_differences(model, name):
    """∂p/∂q equals central finite differences of the positions."""
    q, _, _ = random_state(model, seed=4, n=3)
    jac = model.point_jacobian(q, name)
    h = 1e-6
    for i in range(9):
        dq = np.zeros(9)
        dq[i] = h
        fd = (model.point(q + dq, name) - model.point(q - dq, name)) / (2 * h)
        np.testing.assert_allclose(jac[..., i], fd, atol=1e-8, err_msg=f"column {i}")


def test_stance_state_keeps_the_foot_fixed(model):
    """With stance_state, A_c q̇ = 0 and A_c q̈ + H_c = 0 (eq. 16): the foot does not move."""
    q, qd, qdd = random_state(model, seed=5)
    ac = model.contact_jacobian(q)
    np.testing.assert_allclose(
        model.point(q, "stance_ankle"), [[0.0, ROBOT.ankle_height]] * len(q), atol=1e-12
    )
    np.testing.assert_allclose(ac @ qd[..., None], 0.0, atol=1e-12)
    np.testing.assert_allclose(
        (ac @ qdd[..., None])[..., 0] + model.contact_bias(q, qd), 0.0, atol=1e-10
    )


@settings(max_examples=60, deadline=None)
@given(
    knee=st.sampled_from(biped.KNEES),
    distance=st.floats(0.45, 0.8346),
    direction=st.floats(-0.6, 0.6),
    radius=st.floats(0.0, 0.12),
)
def test_inverse_geometry_round_trip(knee, distance, direction, radius):
    """leg_angles returns a knee bent forward that puts the hip where asked."""
    robot = biped.Robot.paper().__class__(**{**ROBOT.to_dict(), "r1": radius, "r2": 0.6 * radius})
    model = biped.Biped(robot, knee)
    hip = distance * np.array([np.sin(direction), np.cos(direction)])
    shank, thigh = model.leg_angles(hip)
    assert thigh - shank >= 0.0
    q, _, _ = model.stance_state([0.0, shank, thigh, 0.0, 0.0, 0.0])
    np.testing.assert_allclose(q[[XH, ZH]] - [0.0, ROBOT.ankle_height], hip, atol=1e-10)


def test_inverse_geometry_is_vectorised_and_rejects_unreachable(model):
    """Batches solve at once; a hip beyond the leg's reach is a clear error."""
    hips = np.array([[0.1, 0.8], [-0.2, 0.7], [0.0, 0.6]])
    angles = model.leg_angles(hips)
    assert angles.shape == (3, 2)
    low, high = model.leg_reach()
    assert high == pytest.approx(ROBOT.shank_length + ROBOT.thigh_length)
    with pytest.raises(biped.UnreachableError, match="out of reach: allowed"):
        model.leg_angles([0.0, high + 0.01])


def test_swap_legs_is_an_involution(model):
    """Swapping twice gives back the posture; the new stance ankle is at x = 0."""
    q, qd, _ = random_state(model, seed=6)
    new_q, new_qd = swap_legs(model, q, qd)
    np.testing.assert_allclose(model.point(new_q, "stance_ankle")[:, 0], 0.0, atol=1e-12)
    np.testing.assert_allclose(
        model.point(new_q, "swing_toe"),
        model.point(q, "stance_toe") - model.point(q, "swing_ankle") * [1, 0],
        atol=1e-12,
    )
    back_q, back_qd = swap_legs(model, new_q, new_qd)
    shift = model.point(q, "stance_ankle")[:, 0]
    np.testing.assert_allclose(back_q[:, :XH], q[:, :XH])
    np.testing.assert_allclose(back_q[:, XH], q[:, XH] - shift, atol=1e-12)
    np.testing.assert_allclose(back_qd, qd)
    assert new_q[0, QP2] == q[0, 0]
