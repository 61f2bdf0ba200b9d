line style: thick
