def draw(name, results, rig, out):
    return []
