# The built-in scene from the side at 320x180: spheres in front of spheres.
# The visibility pass: fragments that passed the depth test and were later
# hidden are never shaded; the winner of each sample is shaded once.
frame
pixel 156 12
pixel 162 78
stage shaded
stage msaa
