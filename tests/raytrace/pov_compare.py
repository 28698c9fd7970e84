"""pov_compare.py - povray's picture of a converted scene against vwalls render's, for
the nff2pov tests (nff2pov.sh).

usage: pov_compare.py POV.ppm VWALLS.pfm --covered R,G,B
         the same pixels covered (not the background colour R,G,B, within 0.02)
       pov_compare.py POV.ppm VWALLS.pfm --within TOL
         every pixel's channels within TOL (vwalls' clamped to [0, 1])
Exit status 1 when they differ, with what differs on stdout.
"""
import struct
import sys


def header(d, n):
    """The first n header tokens of a PPM or PFM ('#' comments skipped) and the offset
    after the single blank that ends the header."""
    toks, i = [], 0
    while len(toks) < n:
        if d[i:i + 1] == b'#':
            i = d.index(b'\n', i) + 1
        elif d[i:i + 1].isspace():
            i += 1
        else:
            j = i
            while not d[j:j + 1].isspace():
                j += 1
            toks.append(d[i:j])
            i = j
    return toks, i + 1


def load(ppm, pfm):
    """The two pictures as rows (top first) of RGB tuples in [0, 1] (POV-Ray's) and as
    rendered (vwalls' floats)."""
    d = open(ppm, 'rb').read()
    (magic, w, h, mx), at = header(d, 4)
    assert magic == b'P6' and int(mx) == 255, magic
    w, h = int(w), int(h)
    pov = [[tuple(d[at + 3 * (y * w + x) + k] / 255 for k in range(3)) for x in range(w)]
           for y in range(h)]
    d = open(pfm, 'rb').read()
    (magic, w2, h2, scale), at = header(d, 4)
    assert magic == b'PF' and (int(w2), int(h2)) == (w, h), magic
    v = struct.unpack(('<' if float(scale) < 0 else '>') + '%df' % (3 * w * h), d[at:at + 12 * w * h])
    vw = [[tuple(v[3 * (y * w + x) + k] for k in range(3)) for x in range(w)] for y in range(h)][::-1]
    return w, h, pov, vw


def covered(pov, vw, w, h, bg):
    def cov(c):
        return any(abs(c[k] - bg[k]) > 0.02 for k in range(3))
    diff = [(x, y) for y in range(h) for x in range(w) if cov(pov[y][x]) != cov(vw[y][x])]
    n = sum(cov(vw[y][x]) for y in range(h) for x in range(w))
    print('%d of %d pixels covered by vwalls; %d differ in POV-Ray' % (n, w * h, len(diff)))
    if diff:
        for y in range(h):  # X: differs, #: covered, .: background (vwalls)
            print(''.join('X' if (x, y) in diff else '#' if cov(vw[y][x]) else '.' for x in range(w)))
    return not diff


def within(pov, vw, w, h, tol):
    clamp = [[tuple(min(1.0, max(0.0, c)) for c in p) for p in row] for row in vw]
    bad = [(x, y) for y in range(h) for x in range(w)
           if max(abs(pov[y][x][k] - clamp[y][x][k]) for k in range(3)) > tol]
    print('%d of %d pixels differ by more than %g' % (len(bad), w * h, tol))
    for x, y in bad[:5]:
        print('  pixel %d,%d: vwalls %s, POV-Ray %s' % (x, y, clamp[y][x], pov[y][x]))
    return not bad


if __name__ == '__main__':
    if len(sys.argv) != 5 or sys.argv[3] not in ('--covered', '--within'):
        sys.exit(__doc__)
    w, h, pov, vw = load(sys.argv[1], sys.argv[2])
    if sys.argv[3] == '--covered':
        ok = covered(pov, vw, w, h, [float(x) for x in sys.argv[4].split(',')])
    else:
        ok = within(pov, vw, w, h, float(sys.argv[4]))
    sys.exit(0 if ok else 1)
