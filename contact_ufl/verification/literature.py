"""Published results of the verification problems (shallow ironing, mu = 0.3)."""

#: Global friction coefficients |Fx/Fy| at t = 1.5 of the shallow ironing problem with
#: mu = 0.3 in the literature, as compiled by the solids4foam tutorial ``shallowIroning``
#: (Batistic, Cardiff & Tukovic 2022, Table 1 there).
IRONING_LITERATURE = {
    "Poulios & Renard 2015": 0.30,
    "Batistic et al. 2022": 0.32,
    "Houssein 2022": 0.32,
    "Code_Aster SSNP153": 0.34,
    "Hartmann et al. 2009": 0.38,
    "Yastrebov 2011": 0.47,
    "Fischer & Wriggers 2006": 0.53,
}

#: Reaction forces on the indenter's top (magnitudes, per unit thickness in the units of E
#: times length) of the shallow ironing problem with mu = 0.3 in the literature:
#: ``(Fy, Fx)`` at t = 1.0 (end of pressing) and at t = 1.5 (steady sliding), read off the
#: published curves by the solids4foam tutorial ``shallowIroning`` (Table 2 there; its
#: newtons on a 1 mm thick domain with lengths in mm are 1e-6 of these units).
IRONING_FORCES = {
    "Poulios & Renard 2015": ((2.679e8, 0.553e8), (3.374e8, 1.021e8)),
    "Batistic et al. 2022": ((3.164e8, 0.550e8), (3.951e8, 1.227e8)),
    "Code_Aster SSNP153": ((3.320e8, 0.710e8), (4.210e8, 1.433e8)),
    "Hartmann et al. 2009": ((3.195e8, 0.672e8), (4.084e8, 1.602e8)),
    "Yastrebov 2011": ((2.897e8, 0.585e8), (3.595e8, 1.708e8)),
    "Fischer & Wriggers 2006": ((2.979e8, 0.621e8), (3.651e8, 1.888e8)),
}

#: The 3D ironing problem (a cylindrical die pressed 1.4 into a Neo-Hookean slab 9 x 4 x 3,
#: then slid 4 along it; mu = 0.3): Puso & Laursen 2004 (CMAME 193, 601-629, example 2;
#: report https://www.osti.gov/servlets/purl/15013715), whose data the LLNL Smith example
#: ``die-on-slab`` restates. Its force histories are published as curves only; no digitised
#: values were reachable, so there is no reference to compare with yet (TODO).
IRONING_3D = {
    "source": "Puso & Laursen 2004, CMAME 193:601-629, example 2 (ironing)",
    "data_from": "LLNL Smith examples/die-on-slab (README and source)",
    "status": "TODO: force histories published as curves only; no digitised values found",
    "forces": {},
}
