"""Finding the lumen: from a point (its values, rays, growth with explosion control, tagged fluid) or from a
segmentation, and the wall a flythrough draws around it."""
