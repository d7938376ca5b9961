"""Plain-Python references for the vectorised geometry in kitsuke.dressing (slow, obvious, for tests only)."""

from __future__ import annotations


def _orient(p, q, r) -> float:
    return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])


def _on_segment(p, q, r, eps) -> bool:
    """r lies on segment pq (given it is collinear with it)."""
    return (
        min(p[0], q[0]) - eps <= r[0] <= max(p[0], q[0]) + eps
        and min(p[1], q[1]) - eps <= r[1] <= max(p[1], q[1]) + eps
    )


def segments_intersect(p1, p2, q1, q2, eps=1e-9) -> bool:
    """Two closed segments intersect or touch (the textbook orientation test)."""
    d1, d2 = _orient(q1, q2, p1), _orient(q1, q2, p2)
    d3, d4 = _orient(p1, p2, q1), _orient(p1, p2, q2)
    if ((d1 > eps and d2 < -eps) or (d1 < -eps and d2 > eps)) and (
        (d3 > eps and d4 < -eps) or (d3 < -eps and d4 > eps)
    ):
        return True
    return (
        (abs(d1) <= eps and _on_segment(q1, q2, p1, eps))
        or (abs(d2) <= eps and _on_segment(q1, q2, p2, eps))
        or (abs(d3) <= eps and _on_segment(p1, p2, q1, eps))
        or (abs(d4) <= eps and _on_segment(p1, p2, q2, eps))
    )


def point_in_triangle(p, a, b, c, eps=1e-9) -> bool:
    s1, s2, s3 = _orient(a, b, p), _orient(b, c, p), _orient(c, a, p)
    return (s1 >= -eps and s2 >= -eps and s3 >= -eps) or (s1 <= eps and s2 <= eps and s3 <= eps)


def triangles_crossed_reference(points, triangles) -> set[int]:
    """Indices of triangles (F, 3, 2) that the polyline (n, 2) crosses or touches: a segment end inside the
    triangle, or the segment meeting one of its edges."""
    hit = set()
    for t, (a, b, c) in enumerate(triangles):
        for p, q in zip(points[:-1], points[1:]):
            if (
                point_in_triangle(p, a, b, c)
                or point_in_triangle(q, a, b, c)
                or segments_intersect(p, q, a, b)
                or segments_intersect(p, q, b, c)
                or segments_intersect(p, q, c, a)
            ):
                hit.add(t)
                break
    return hit
