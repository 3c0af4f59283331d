"""Published results of the verification problems (2D shallow ironing, mu = 0.3; what the
literature has of the 3D ironing)."""

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
#: then slid 4 along it; mu = 0.3): Puso & Laursen 2004, "A mortar segment-to-segment
#: frictional contact method for large deformations" (CMAME 193, 4891-4913; the report
#: UCRL-JRNL-200667, https://www.osti.gov/servlets/purl/15013715), example 2 ("ironing"),
#: whose data the LLNL Smith example ``die-on-slab`` restates. What a search of public
#: pages, documentation and code found (``sources``): the publication and the later
#: 3D large-sliding papers show their force histories as figures only; no table, data file
#: or digitised curve of them was found, so there is no published number to compare with
#: and ``forces`` is empty (no spread can be given). The checks that need no publication
#: are in benchmarks/ironing_3d.py: Coulomb's ratio of the frictional to the normal force
#: (mu = 0.3) and the mirror symmetry of the frictionless force history (mu = 0). The
#: published large-sliding force histories the 3D machinery is compared with are those of
#: the 2D shallow ironing (:data:`IRONING_FORCES`), solved in plane strain on an extruded 3D
#: mesh (benchmarks/ironing_plane_strain.py).
IRONING_3D = {
    "source": "Puso & Laursen 2004, CMAME 193:4891-4913 (UCRL-JRNL-200667), example 2",
    "data_from": "LLNL Smith examples/die-on-slab (README and source)",
    "status": (
        "curves only: the force histories are published as figures, no digitised values "
        "were found (no reference numbers, no spread)"
    ),
    "sources": {
        "Puso & Laursen 2004 (UCRL-JRNL-200667, OSTI 15013715)": (
            "the problem's data; force histories of the ironing as figures only (the "
            "report's text was reachable only in part: title pages)"
        ),
        "LLNL Smith examples/die-on-slab README": (
            "geometry, materials, loading (press 1.4 over t = 0-0.2, slide 4 over "
            "0.2-1.5), penalty 500, mu = 0.3; expected behaviour in words only, no forces"
        ),
        "Temizer, Wriggers & Hughes 2012 (CMAME; ICES report 11-16)": (
            "3D mortar frictional contact (NURBS) with large-sliding examples; abstract "
            "only reachable, forces as figures"
        ),
        "De Lorenzis, Wriggers & Zavarise 2012 (Comput Mech 49:1-20)": (
            "3D frictionless mortar large sliding (NURBS); traction histories as figures"
        ),
        "KratosMultiphysics/Examples ironing_with_die_3D": (
            "a different die (a full cylinder); a comparison picture, no numbers"
        ),
        "MOOSE contact tests": "the ironing tests are 2D; the 3D mortar test is a block",
        # further sources (pages, documentation, code, issue trackers), none with numbers:
        "KratosMultiphysics/Examples validation/shallow_ironing_3D (Mataix Ferrandiz)": (
            "the 2D shallow ironing extruded in 3D with u_z = 0 on the side faces (what "
            "benchmarks/ironing_plane_strain.py does), frictionless 'literature' set; "
            "compared with Poulios & Renard's curve in a picture only, no numbers"
        ),
        "Code_Aster validation tests (stored copies of astest/)": (
            "searched for 'repassage' and 'ironing': only SSNP153, the 2D shallow ironing "
            "(already in IRONING_FORCES); no 3D large-sliding test with published reference "
            "forces found"
        ),
        "Abaqus Benchmarks/Verification manuals, NAFEMS 3D contact benchmarks": (
            "not among the stored pages or documentation; the NAFEMS CGS-4 test found "
            "(FrontISTR, analytical sliding limit F/G = 0.412371) is small sliding"
        ),
        "4C and MOOSE 3D contact tests": (
            "tutorials and regression tests against their own earlier results (4C "
            "tutorial_contact_3d, MOOSE frictionless-mortar-3d), no published force history"
        ),
        "Doca et al. 2014 (IJSS), Areias et al. 2004 (IJNME 61:1107)": (
            "3D finite-strain frictional contact examples; only abstracts or first pages "
            "reachable, no force values in them"
        ),
    },
    "forces": {},
}
