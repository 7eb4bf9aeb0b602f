"""The floor (and, for the mirror variant, the orb) materials that the hall and the Sponza
scenes share: Voorhuis' SponzaGlossyFloor and SponzaPureSpeculars (seed 001, section 3.2)."""


def floor_materials(variant):
    """TOML for `floor` (glossy) or `floor` and `orb` (mirror)."""
    if variant == "glossy":
        return '''
# The glossy floor: 40 % a glossy lobe (hardness 0.3, about a Beckmann roughness of 0.08), 60 %
# a warm diffuse stone.
[[material]]
name = "floor"
layers = [
    { weight = 0.4, color = [0.9, 0.9, 0.9], hardness = 0.3 },
    { weight = 0.6, color = [0.45, 0.4, 0.34] },
]
'''
    return '''
[[material]]
name = "floor"
type = "mirror"
color = [0.85, 0.85, 0.85]

[[material]]
name = "orb"
type = "mirror"
color = [0.95, 0.95, 0.95]
'''
