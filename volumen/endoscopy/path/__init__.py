"""The path through the lumen: the centerline, poses and keyframes, manual and guided navigation, where the camera
looks, and collisions with the wall."""
