"""Questions beyond the two papers: paper 1's open question (hybrid), sets
beyond one machine (distributed), the peers of 2026 (field) and scipy's
Delaunay and interpolation surface (scipy_surface)."""
TITLE = "Beyond the papers"
