executable: shadowpyramid -e commfile.e light.spec
communication type: files
turtle position: P: %f %f %f
