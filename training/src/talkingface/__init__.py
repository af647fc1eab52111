"""Training toolkit for the in-browser GAVA talking face.

Data flow (paper Fig. 2): audio -> log-Mel -> content / pose encoders ->
hierarchical vertex tokens -> neighbour-masked attention -> displacement + pose
-> posed mesh y = T_p (I + O). The browser runs the exported version of the
same graph; shared constants live in models/manifest.json.
"""
