// bvh: sources land here
