"""Particles along a line: whether a frame's particles form a column or a layer (at most two
particles across, nothing to triangulate), and a field along a vertical line through a run's
frames, in depth below the top of the particles at the first frame.
"""
import numpy as np

# Coordinates closer than this fraction of the domain's size are one coordinate.
SAME = 1e-9


def planar(frame):
    """The frame's particle positions as an n x 2 array (x, y)."""
    xy = frame["coordinates"]
    return xy[:, :2] if xy.shape[1] >= 2 else np.column_stack([xy[:, 0], np.zeros(len(xy))])


def tolerance(xy):
    return SAME * max(1.0, float(np.ptp(xy))) if xy.size else SAME


def distinct(values, tol):
    """The sorted values with those closer than `tol` to the one before merged."""
    v = np.sort(values)
    return v[np.concatenate(([True], np.diff(v) > tol))] if v.size else v


def group_ids(values, tol):
    """For each value, the index of its group in `distinct(values, tol)`."""
    order = np.argsort(values)
    ids = np.empty(len(values), dtype=int)
    ids[order] = np.concatenate(([0], np.cumsum(np.diff(values[order]) > tol))) if len(values) else []
    return ids


def line_axis(frame):
    """1 when the particles form a vertical column at most two particles wide, 0 for such a
    horizontal layer, None for a 2-D cloud a triangulation can cover."""
    xy = planar(frame)
    tol = tolerance(xy)
    if len(distinct(xy[:, 0], tol)) <= 2:
        return 1
    if len(distinct(xy[:, 1], tol)) <= 2:
        return 0
    return None


def component(values, index):
    """A scalar field as is; one column (0 = x, 1 = y) of a vector field."""
    return values if values.ndim == 1 else values[:, index]


def averaged_along(coordinate, values, tol):
    """(coordinates, values): the values of particles at one coordinate averaged, in order."""
    ids = group_ids(coordinate, tol)
    count = np.bincount(ids)
    return np.bincount(ids, coordinate) / count, np.bincount(ids, values) / count


class VerticalLine:
    """The vertical line x = X through a run's frames: the particles within half a particle
    column spacing of X (measured on the first frame and kept, so the band follows particles
    that move), their values at one height averaged. A line midway between two particle
    columns (the axis of a column two particles wide) averages both."""

    def __init__(self, first_frame, x=None):
        xy = planar(first_frame)
        self.tol = tolerance(xy)
        columns = distinct(xy[:, 0], self.tol)
        self.x = 0.5 * (columns[0] + columns[-1]) if x is None else float(x)
        spacing = float(np.min(np.diff(columns))) if len(columns) > 1 else np.inf
        self.half_width = 0.5 * spacing * (1 + 1e-6) + self.tol
        if np.min(np.abs(columns - self.x)) > self.half_width:
            raise ValueError(f"the line x = {self.x:g} m misses the particles (x from {columns[0]:g} to "
                             f"{columns[-1]:g} m)")
        heights = distinct(xy[self.band(xy), 1], self.tol)
        # The top of the material: the highest particle centre plus half a particle's height.
        self.surface = heights[-1] + (0.5 * float(np.min(np.diff(heights))) if len(heights) > 1 else 0.0)

    def band(self, xy):
        return np.abs(xy[:, 0] - self.x) <= self.half_width

    def profile(self, frame, values):
        """(depth, values) of one frame, depth increasing downwards from the first frame's top;
        `values` holds one value per particle of the frame."""
        xy = planar(frame)
        inside = self.band(xy)
        heights, mean = averaged_along(xy[inside, 1], values[inside], self.tol)
        return (self.surface - heights)[::-1], mean[::-1]

    def time_depth(self, frames, values_of):
        """(times, depths, grid) with grid[k, j] the value of frame k at depths[j] (the first
        frame's depths; NaN where a frame has no particles): `values_of(frame)` gives the
        per-particle values."""
        depths, _ = self.profile(frames[0], values_of(frames[0]))
        grid = np.full((len(frames), len(depths)), np.nan)
        for k, frame in enumerate(frames):
            d, v = self.profile(frame, values_of(frame))
            if len(d):
                grid[k] = np.interp(depths, d, v, left=np.nan, right=np.nan)
        return np.array([frame["time"] for frame in frames]), depths, grid
