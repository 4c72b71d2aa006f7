# --near 6.5: the near plane cuts the floor in front of the camera.
frame
tri 98368
tri 98369
pixel 640 700
pixel 100 715
