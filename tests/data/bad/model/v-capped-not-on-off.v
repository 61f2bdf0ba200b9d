line style: cylinder
capped cylinders: yes
