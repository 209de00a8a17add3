"""The certificate of a move, and the audit behind ``adept-traj verify``.

:func:`certify` (:mod:`~adept_traj.certification.certificate`) samples a move densely
(:mod:`~adept_traj.certification.dense_trajectory`), checks every joint limit
(:mod:`~adept_traj.certification.limit_check`) and bounds the distances between the
samples (:mod:`~adept_traj.certification.continuous`), the robot's own links included
(:mod:`~adept_traj.certification.self_distance`); :func:`certify_members`
(:mod:`~adept_traj.certification.member_certificate`) certifies a front's members;
:func:`check_rest_poses` (:mod:`~adept_traj.certification.rest_poses`) the start and goal
before any search. :func:`~adept_traj.certification.audit.audit` recomputes a saved
result's values (with :mod:`~adept_traj.certification.mismatches`); it reads a
:class:`~adept_traj.results.PlanningResult`, so it is imported from its module
(``from adept_traj.certification.audit import audit``, or ``adept_traj.audit``), not from
this package, which the results package imports."""

from __future__ import annotations

from adept_traj.certification.certificate import (
    DEFAULT_RATE_HZ,
    Certificate,
    certificate_bytes,
    certify,
    check_certificate_memory,
)
from adept_traj.certification.continuous import (
    CONTINUOUS,
    DEFAULT_MAX_DEPTH,
    DistanceGuarantee,
    SampledMove,
    continuous_distance,
    continuous_self_distance,
    obstacle_jump_intervals,
    obstacle_speeds,
    sampled_move,
    solid_lever_arms,
)
from adept_traj.certification.dense_trajectory import (
    BATCH_SAMPLES,
    BATCH_VALUES,
    DenseStates,
    DenseTrajectory,
    batch_samples,
    dense_samples,
)
from adept_traj.certification.limit_check import DEFAULT_TOLERANCE, LimitCheck
from adept_traj.certification.member_certificate import (
    FRONT_INFLUENCE_ABOVE_MARGIN,
    MemberCertificate,
    certify_member,
    certify_members,
    certifying_problem,
)
from adept_traj.certification.mismatches import AUDIT_RTOL, Mismatch
from adept_traj.certification.rest_poses import check_rest_poses, rest_pose_contacts
from adept_traj.certification.self_distance import SelfDistance, self_distance

__all__ = [
    "AUDIT_RTOL",
    "BATCH_SAMPLES",
    "BATCH_VALUES",
    "CONTINUOUS",
    "DEFAULT_MAX_DEPTH",
    "DEFAULT_RATE_HZ",
    "DEFAULT_TOLERANCE",
    "FRONT_INFLUENCE_ABOVE_MARGIN",
    "Certificate",
    "DenseStates",
    "DenseTrajectory",
    "DistanceGuarantee",
    "LimitCheck",
    "MemberCertificate",
    "Mismatch",
    "SampledMove",
    "SelfDistance",
    "batch_samples",
    "certificate_bytes",
    "certify",
    "certify_member",
    "certify_members",
    "certifying_problem",
    "check_certificate_memory",
    "check_rest_poses",
    "continuous_distance",
    "continuous_self_distance",
    "dense_samples",
    "obstacle_jump_intervals",
    "obstacle_speeds",
    "rest_pose_contacts",
    "sampled_move",
    "self_distance",
    "solid_lever_arms",
]
