"""Where the wall is: the wall as a scalar field with a level, and the compiled first-hit march through it that
collisions, the unfolded view and the scores share."""
