"""Self-contact: a surface searched against itself (the admissibility of pairs)."""

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from contact_ufl.contact import projection
from contact_ufl.contact.projection import SelfContact, closest_points


def _slit_2d(n: int = 40, a: float = 1.0, b: float = 0.06):
    """The boundary of an elliptic hole (half-axes ``a``, ``b``) in a body around it:
    segments traversed clockwise, so that the normal points into the hole (out of the body)."""
    t = -np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    ring = np.stack([a * np.cos(t), b * np.sin(t)], axis=1)
    facet_nodes = np.stack([np.arange(n), (np.arange(n) + 1) % n], axis=1)
    return ring[facet_nodes], facet_nodes


def _slit_3d(b: float = 0.1):
    """A thin box cavity ``[0, 1]^2 x [0, b]``: triangles of its surface, normals inward."""
    g = np.linspace(0.0, 1.0, 6)
    X, Y = np.meshgrid(g, g)
    pts = []
    for z in (0.0, b):
        pts.append(np.stack([X.ravel(), Y.ravel(), np.full(X.size, z)], axis=1))
    pts = np.unique(np.concatenate(pts), axis=0)
    hull = ConvexHull(pts)
    tri = hull.simplices.copy()
    nodes = pts[tri]
    outward = hull.equations[:, :3]
    normal = np.cross(nodes[:, 1] - nodes[:, 0], nodes[:, 2] - nodes[:, 0])
    flip = np.einsum("fd,fd->f", normal, outward) > 0  # make them point inward
    tri[flip] = tri[flip][:, [0, 2, 1]]
    return pts[tri], tri


def _facet_points(nodes: np.ndarray, facet_nodes: np.ndarray):
    """Centroids of the facets as the slave points, with their facets' nodes and normals."""
    points = nodes.mean(axis=1)
    a1 = nodes[:, 1] - nodes[:, 0]
    if nodes.shape[2] == 2:
        n = np.stack([a1[:, 1], -a1[:, 0]], axis=1)
    else:
        n = np.cross(a1, nodes[:, 2] - nodes[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    return points, SelfContact(facet_nodes, facet_nodes, n)


def _brute_force(points, nodes, rule: SelfContact, radius=np.inf):
    """Distance and facet of each point over its admissible facets, one point at a time."""
    centre = projection._Master(nodes).axis
    dist = np.full(len(points), np.inf)
    for p, x in enumerate(points):
        f = np.arange(len(nodes))
        ok = rule.admissible(np.full(f.size, p), f, centre)
        if ok.any():
            proj = closest_points(x[None], nodes[ok], radius)
            dist[p] = proj.distance[0]
    return dist


@pytest.mark.parametrize("slit", [_slit_2d, _slit_3d])
def test_self_contact_matches_brute_force(slit):
    nodes, facet_nodes = slit()
    points, rule = _facet_points(nodes, facet_nodes)
    # without the rule every point finds its own facet at distance zero
    plain = closest_points(points, nodes)
    assert np.all(plain.distance < 1e-12)
    proj = closest_points(points, nodes, self_contact=rule)
    expected = _brute_force(points, nodes, rule)
    assert np.all(proj.facet >= 0)
    np.testing.assert_allclose(proj.distance, expected, rtol=1e-12, atol=1e-14)
    # the partner faces the point: opposed normals, and it is not the point's own facet
    f = proj.facet
    assert np.all(np.einsum("pd,pd->p", proj.normal, rule.point_normals) < 0)
    assert not np.any(f == np.arange(len(points)))
    # the partner is across the slit: the points are in front of it (negative proximity)
    assert np.all(proj.gap < 0)


def test_self_contact_across_an_elliptic_slit():
    """The points of each arc find the other arc across the slit, symmetrically about y = 0."""
    nodes, facet_nodes = _slit_2d(n=80, b=0.05)
    points, rule = _facet_points(nodes, facet_nodes)
    proj = closest_points(points, nodes, self_contact=rule)
    middle = np.abs(points[:, 0]) < 0.9
    assert np.all(np.sign(proj.y[middle, 1]) == -np.sign(points[middle, 1]))
    # the partner of the mirror image (x, -y) of a point is the mirror image of its partner
    mirror = points * [1.0, -1.0]
    image = np.argmin(np.linalg.norm(points[:, None] - mirror[None], axis=2), axis=0)
    np.testing.assert_allclose(points[image], mirror, atol=1e-14)
    np.testing.assert_allclose(proj.y[image], proj.y * [1.0, -1.0], atol=1e-14)
    np.testing.assert_allclose(proj.distance[image], proj.distance, rtol=1e-13)


@pytest.mark.parametrize("slit", [_slit_2d, _slit_3d])
def test_self_contact_blocks_and_order(slit, monkeypatch):
    """Blocks of points and the spatial order map the points to their own facets."""
    nodes, facet_nodes = slit()
    points, rule = _facet_points(nodes, facet_nodes)
    reference = closest_points(points, nodes, self_contact=rule)
    monkeypatch.setattr(projection, "_BLOCK", 7)
    monkeypatch.setattr(projection, "_SORT", 0)
    proj = closest_points(points, nodes, self_contact=rule)
    np.testing.assert_array_equal(proj.facet, reference.facet)
    np.testing.assert_array_equal(proj.distance, reference.distance)


def test_self_contact_within_a_radius():
    """A radius shorter than the slit's width leaves every point unpaired (no fallback to
    the excluded neighbours); a radius just over it pairs the middle points."""
    nodes, facet_nodes = _slit_2d(n=80, b=0.05)
    points, rule = _facet_points(nodes, facet_nodes)
    short = closest_points(points, nodes, radius=0.05, self_contact=rule)
    width = _brute_force(points, nodes, rule)
    np.testing.assert_array_equal(short.facet >= 0, width <= 0.05)
    assert np.count_nonzero(short.facet >= 0) < len(points)
    wide = closest_points(points, nodes, radius=0.11, self_contact=rule)
    np.testing.assert_array_equal(wide.facet >= 0, width <= 0.11)
    np.testing.assert_allclose(wide.distance[wide.facet >= 0], width[width <= 0.11], rtol=1e-12)


def test_self_contact_of_a_flat_surface_finds_nothing():
    """A flat surface never faces itself: no admissible pair."""
    x = np.linspace(0.0, 1.0, 11)
    line = np.stack([x, np.zeros_like(x)], axis=1)
    facet_nodes = np.stack([np.arange(10), np.arange(1, 11)], axis=1)
    nodes = line[facet_nodes]
    points, rule = _facet_points(nodes, facet_nodes)
    proj = closest_points(points, nodes, self_contact=rule)
    assert np.all(proj.facet == -1)


def test_self_contact_shapes_are_checked():
    nodes, facet_nodes = _slit_2d()
    points, rule = _facet_points(nodes, facet_nodes)
    bad = SelfContact(rule.point_nodes[:-1], rule.facet_nodes, rule.point_normals)
    with pytest.raises(ValueError, match="self_contact must hold"):
        closest_points(points, nodes, self_contact=bad)
