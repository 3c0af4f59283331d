"""Contact pairs: what the user writes (:class:`ContactPair`) and the composed terms the
problem assembles for each (:class:`ContactInterface`: slave side, master side, search,
kinematics, normal law and Coulomb law), and the rigid obstacles a pair may have as its
master (:mod:`.obstacles`)."""

from contact_ufl.contact.interface import ContactInterface
from contact_ufl.contact.obstacles import RigidCylinder, RigidObstacle, RigidPlane, RigidSphere
from contact_ufl.contact.pair import ContactPair

__all__ = [
    "ContactInterface",
    "ContactPair",
    "RigidCylinder",
    "RigidObstacle",
    "RigidPlane",
    "RigidSphere",
]
