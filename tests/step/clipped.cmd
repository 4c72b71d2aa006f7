# --near 6.5: the near plane cuts the floor in front of the camera.
frame
tri 98368
tri 98369
# piece 0 and piece 1 of tri 98369
pixel 120 570
pixel 200 556
pixel 640 700
