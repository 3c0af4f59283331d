"""Checked by mypy in tests/test_coupling.py (not a test module): the contact interface
and the volume constraint are structurally the operator's ``Coupling``."""

from contact_ufl.contact.interface import ContactInterface
from contact_ufl.control import VolumeConstraint
from contact_ufl.coupling import Coupling


def couplings(contact: ContactInterface, control: VolumeConstraint) -> list[Coupling]:
    return [contact, control]
