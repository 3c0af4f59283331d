"""Verification: scenes, geometries, analytic solutions, literature tables and runs used by
the tests, benchmarks and verification demos; the library never imports it.

Modules
-------
* :mod:`~contact_ufl.verification.geometries`: gmsh meshes of the benchmark scenes (Hertz,
  curved pairs, patch tests, crossed cylinders, ironing, two beams, a hemispherical indenter).
* :mod:`~contact_ufl.verification.membrane_meshes`: membrane and string meshes built with
  NumPy (sphere octant, tube and ring sectors, drumhead), with named groups.
* :mod:`~contact_ufl.verification.scenes`: those meshes made into scenes (bodies, supports,
  loads, contact pairs) with the data of their reference solutions.
* :mod:`~contact_ufl.verification.analytic`: closed-form references (Hertz, Cattaneo-Mindlin,
  homogeneous deformations, membrane inflation, an inflated tube between two plates, the
  pre-tensioned drumhead and string under pressure).
* :mod:`~contact_ufl.verification.literature`: published tables (shallow ironing).
* :mod:`~contact_ufl.verification.runs`: verification runs shared by tests and benchmarks.
* :mod:`~contact_ufl.verification.taylor_cases`: generic contact states on curved surfaces
  for the Taylor test of the tangent (:func:`contact_ufl.taylor.taylor_test`).
"""
