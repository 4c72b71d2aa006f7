# The built-in scene at 1280x720: the commands of the README's tutorial.
help
frame
pixel 780 380
tri 43470
tile 12 5
draws
draw 0
pixel 640 560
pixel 500 250
pixel 900 200
tri 0
tri 3
upto 20000
stage overdraw
stage wireframe w.png
bogus
pixel 1280 0
quit
pixel 1 1
