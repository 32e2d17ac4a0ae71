"""Views of the wall other than the flythrough: curved planar reformations (and their figure) and the unfolded
wall."""
