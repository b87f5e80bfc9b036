#!/usr/bin/env python3
"""Writes normal.txt: what `spotread -e -x` (ArgyllCMS 3.2.0) prints for 36
readings, two of each of the 18 patches of `atonlab calibrate measure
--grey-levels 9 --colour-levels 4` (see --list-patches), of a GOG display:
L(V) = 0.25 + (100 - 0.25) V^2.2 cd/m2 per channel, sRGB primaries
(IEC 61966-2-1). The second reading of a patch is 0.1 % above the first."""
M = [[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]]
PEAK, BLACK, GAMMA = 100.0, 0.25, 2.2
greys = [0, 255, 32, 64, 96, 128, 159, 191, 223]
patches = [(g, g, g) for g in greys]
for c in range(3):
    for code in (85, 170, 255):
        rgb = [0, 0, 0]
        rgb[c] = code
        patches.append(tuple(rgb))
PROMPT = """
Place instrument on spot to be measured,
and hit [A-Z] to read white and setup FWA compensation (keyed to letter)
[a-z] to read and make FWA compensated reading from keyed reference
'r' to set reference, 's' to save spectrum,
'f' to report cal. refresh rate, 'F' to measure refresh rate
'h' to toggle high res., 'k' to do a calibration
Hit ESC or Q to exit, any other key to take a reading: @key
"""
out = []
for rgb in patches:
    f = [(BLACK + (PEAK - BLACK) * (v / 255.0) ** GAMMA) / PEAK for v in rgb]
    xyz = [PEAK * sum(M[r][c] * f[c] for c in range(3)) for r in range(3)]
    for scale in (1.0, 1.001):
        X, Y, Z = (v * scale for v in xyz)
        s = X + Y + Z
        out.append(PROMPT)
        # spotread.c: printf("\n Result is XYZ: %f %f %f, Yxy: %f %f %f\n", ...)
        out.append("\n Result is XYZ: %f %f %f, Yxy: %f %f %f\n" % (X, Y, Z, Y, X / s, Y / s))
out.append(PROMPT)
open("normal.txt", "w").write("".join(out))
