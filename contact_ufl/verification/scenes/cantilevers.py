"""The two-beam showcase: Neo-Hookean cantilevers, the upper one pushed onto the lower by a
follower force (:func:`beams`), with the beam-theory estimates (:class:`BeamsScene`).
"""

from __future__ import annotations

from dataclasses import dataclass

from mpi4py import MPI

from contact_ufl.contact import ContactPair
from contact_ufl.loads import Dirichlet, FollowerForce
from contact_ufl.materials import (
    NeoHookean,
)
from contact_ufl.scene import Scene
from contact_ufl.verification import geometries
from contact_ufl.verification.scenes._common import _solids


@dataclass
class BeamsScene:
    """The two-beam showcase scene and the data of its beam-theory estimates."""

    scene: Scene
    geometry: geometries.BeamPair
    E: float
    nu: float
    load: float

    @property
    def bending_stiffness(self) -> float:
        """``EI`` of the upper beam (bending towards the lower one)."""
        g = self.geometry
        return self.E * g.width * g.height**3 / 12.0

    @property
    def lower_bending_stiffness(self) -> float:
        """``EI`` of the lower beam."""
        g = self.geometry
        return self.E * g.lower_width * g.lower_height**3 / 12.0

    def two_springs(self, P: float) -> tuple[float, float]:
        """Beam-theory estimate ``(N, w)`` of the contact force and the upper tip deflection.

        The upper beam is a cantilever of length ``L`` with tip stiffness ``k1 = 3 EI / L^3``;
        the lower one, loaded at ``a = lower_arm`` from its clamp, has ``k2 = 3 EI_2 / a^3``.
        Contact starts at ``P_c = k1 gap``; then ``N = (P - P_c) k2 / (k1 + k2)`` and the tip
        deflects by ``gap + N / k2`` (before, by ``P / k1`` and ``N = 0``). A point contact:
        it holds while only the tip corner touches (with ``clamps = "opposite"``, or at
        small load).
        """
        g = self.geometry
        k1 = 3.0 * self.bending_stiffness / g.length**3
        k2 = 3.0 * self.lower_bending_stiffness / g.lower_arm**3
        P_c = k1 * g.gap
        if P <= P_c:
            return 0.0, P / k1
        N = (P - P_c) * k2 / (k1 + k2)
        return N, g.gap + N / k2


def beams(
    mu: float = 0.0,
    load: float = 5.0,
    divisions: int = 4,
    E: float = 1.0e3,
    nu: float = 0.3,
    geometry: geometries.BeamPair | None = None,
    eps_factor: float = 0.1,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> BeamsScene:
    """Two Neo-Hookean cantilevers, the upper one pushed at its free tip by a follower force.

    The beams of :func:`~contact_ufl.verification.geometries.beams_3d` (by default clamped on
    the same side, the lower one nearer the upper tip:
    :class:`~contact_ufl.verification.geometries.BeamPair`). The free end section of the upper
    beam carries the follower force :class:`FollowerForce` of magnitude ``load * t * EI / L^2``
    (``t`` the pseudo-time), directed along the carried reference direction ``-e_z``: it stays
    perpendicular to the deformed beam axis. The upper beam bends down and its tip meets the
    lower beam; the lower beam, pressed by a shorter lever, turns faster, and the upper beam's
    underside bends onto it and slides along it (with ``clamps = "opposite"`` only the tip
    corner touches). Slave: the bottom of the upper beam above the lower one; master: the top of
    the lower beam from ``master_start``; ``eps_N = eps_factor E / h`` with ``h`` the upper
    element size.

    Parameters
    ----------
    mu
        Friction coefficient.
    load
        Final follower force in units of ``EI / L^2``.
    divisions
        Hexahedra through the height of each beam.
    E, nu
        Neo-Hookean material of both beams.
    geometry
        Lengths (default :class:`contact_ufl.verification.geometries.BeamPair`).
    eps_factor
        Scale of the augmentation parameter. The default 0.1 keeps ``eps_N`` nearer the
        stiffness of slender beams than ``E / h`` (which is the stiffness scale of a solid):
        with ``eps_factor = 1`` the first Newton iterate at the first touch penetrates so
        deeply that the active set cycles and the step is cut back.
    """
    geometry = geometry or geometries.BeamPair()
    sm = geometries.beams_3d(geometry, divisions=divisions, comm=comm)
    material = NeoHookean(E, nu)
    EI = E * geometry.width * geometry.height**3 / 12.0
    P_end = load * EI / geometry.length**2
    h = geometry.height / divisions
    pair = ContactPair(
        "upper_contact",
        "lower_contact",
        eps_N=eps_factor * E / h,
        mu=mu,
        search_radius=geometry.gap + geometry.height,
        quadrature_degree=3,
        quadrature_rule="lobatto",
    )
    scene = Scene.from_mesh_data(
        sm,
        bodies=_solids(upper=material, lower=material),
        contacts=[pair],
        dirichlet=[Dirichlet(clamp, (0.0, 0.0, 0.0)) for clamp in ("upper_clamp", "lower_clamp")],
        loads=[FollowerForce("upper_tip", lambda t: P_end * t, (0.0, 0.0, -1.0))],
    )
    return BeamsScene(scene, geometry, E, nu, load)
