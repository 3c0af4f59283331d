"""Contact pairs: what the user writes (:class:`ContactPair`) and the composed terms the
problem assembles for each (:class:`ContactInterface`: slave side, master side, search,
kinematics, normal law and Coulomb law)."""

from contact_ufl.contact.interface import ContactInterface
from contact_ufl.contact.pair import ContactPair

__all__ = ["ContactInterface", "ContactPair"]
