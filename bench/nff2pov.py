#!/usr/bin/env python3
"""nff2pov.py - converts an NFF scene to POV-Ray 3.7 SDL for bench/raytrace.sh, matching
vwalls render's conventions: no ambient, diffuse = colour * Kd, Phong highlight Ks with
exponent Shine, mirror reflection Ks, transmission T with ior, lights without colour at
1/sqrt(#lights), linear output (assumed_gamma 1), the same camera (NFF angle is the
vertical field of view; POV's is horizontal) and a right-handed image. Polygons of more
than three corners become POV-Ray polygons (drawn concave or not), pp ones smooth
triangles by ear clipping: a fan from the first corner covers a concave polygon's
notches.

The extension lines vwalls writes after an 'f' (docs/raytrace.md) are converted as far
as POV-Ray can follow them, each from where it stands (objects before it keep the
material they had):
  '#vw Ks r g b'  highlight and mirror weight per channel. The mirror is exact
                  (reflection rgb). POV-Ray's phong has one amount for every channel
                  (times the light's colour), or with 'metallic' times the pigment's
                  colour: equal channels are exact, channels in proportion to the 'f'
                  colour are exact with metallic; other colours get the channels' mean,
                  said on stderr.
  '#vw Kr r g b'  the mirror weight alone (reflection rgb): exact.
  '#vw Ke r g b'  emission, added whatever the lights. POV-Ray's emission is scaled by
                  the pigment's colour and by (1 - transmit), so it is written divided
                  by them: exact, except in a channel where the 'f' colour is 0 (or
                  T is 1), which POV-Ray cannot make emit; said on stderr, and that
                  channel emits nothing.

usage: nff2pov.py SCENE.nff WIDTH HEIGHT DEPTH > SCENE.pov
"""
import math
import sys


def main():
    path, width, height, depth = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
    # NFF is read by tokens, not lines; '#' starts a comment to the end of the line.
    # The extension lines become a token of their own ('#vwKs', '#vwKr', '#vwKe') and
    # their numbers.
    toks = []
    with open(path) as f:
        for line in f:
            w = line.split()
            if len(w) == 5 and w[0] == '#vw' and w[1] in ('Ks', 'Kr', 'Ke'):
                toks.extend(['#vw' + w[1]] + w[2:])
                continue
            toks.extend(line.split('#', 1)[0].split())
    pos = 0

    def nxt():
        nonlocal pos
        pos += 1
        return toks[pos - 1]

    def num():
        return float(nxt())

    def vec():
        return (num(), num(), num())

    cam = {'from': (0, 0, 5), 'at': (0, 0, 0), 'up': (0, 1, 0), 'angle': 45.0}
    bg = (0, 0, 0)
    # Per material: the 'f' values, and the highlight, mirror and emission colours.
    lights, objects, out_mats, spec, mirror, emit = [], [], [], [], [], []
    mat, used = None, False  # used: an object has the current material
    while pos < len(toks):
        t = nxt()
        used = used or t in ('s', 'c', 'p', 'pp')
        if t == 'v':
            continue
        if t in ('from', 'at', 'up'):
            cam[t] = vec()
        elif t == 'angle':
            cam['angle'] = num()
        elif t == 'hither':
            num()
        elif t == 'resolution':
            num(), num()
        elif t == 'b':
            bg = vec()
        elif t == 'l':
            p = vec()
            col = None
            # An optional colour: three more numbers before the next keyword.
            if pos + 2 < len(toks) and all(_isnum(x) for x in toks[pos:pos + 3]):
                col = vec()
            lights.append((p, col))
        elif t == 'f':
            r, g, b, kd, ks, shine, tr, ior = (num() for _ in range(8))
            mat, used = len(out_mats), False
            out_mats.append((r, g, b, kd, ks, shine, tr, ior))
            spec.append((ks, ks, ks))
            mirror.append((ks, ks, ks))
            emit.append((0.0, 0.0, 0.0))
        elif t in ('#vwKs', '#vwKr', '#vwKe'):
            # Ks sets the mirror weight too (NFF's Ks weights both); Kr, after it, alone.
            rgb = vec()
            if mat is None:
                continue  # vwalls refuses it ('before any f'); nothing to convert
            if used:  # as vwalls: the objects before it keep their material
                for a in (out_mats, spec, mirror, emit):
                    a.append(a[mat])
                mat, used = len(out_mats) - 1, False
            if t == '#vwKs':
                spec[mat] = mirror[mat] = rgb
            elif t == '#vwKr':
                mirror[mat] = rgb
            else:
                emit[mat] = rgb
        elif t == 's':
            c = vec()
            objects.append('sphere { %s, %r @M%d@ }' % (_v(c), num(), mat))
        elif t == 'c':
            b0, r0 = vec(), num()
            a0, r1 = vec(), num()
            shape = ('cylinder { %s, %s, %r open @M%d@ }' % (_v(b0), _v(a0), abs(r0), mat)
                     if abs(r0) == abs(r1) else
                     'cone { %s, %r, %s, %r open @M%d@ }' % (_v(b0), abs(r0), _v(a0),
                                                                        abs(r1), mat))
            objects.append(shape)
        elif t in ('p', 'pp'):
            n = int(nxt())
            vs, ns = [], []
            for _ in range(n):
                vs.append(vec())
                if t == 'pp':
                    ns.append(vec())
            if t == 'p' and n > 3:
                # POV-Ray's polygon fills by the even-odd rule, so a concave polygon (the
                # SPD gears' faces) is drawn as it is; a fan from the first corner would
                # also cover the notches. Closed by repeating the first corner.
                objects.append('polygon { %d, %s @M%d@ }' % (
                    n + 1, ', '.join(_v(x) for x in vs + vs[:1]), mat))
            elif t == 'p':
                objects.append('triangle { %s, %s, %s @M%d@ }' % (_v(vs[0]), _v(vs[1]), _v(vs[2]), mat))
            else:
                # A polygon has no vertex normals: smooth triangles from ear clipping.
                for a, b, c in _triangulate(vs):
                    objects.append('smooth_triangle { %s, %s, %s, %s, %s, %s @M%d@ }' % (
                        _v(vs[a]), _v(ns[a]), _v(vs[b]), _v(ns[b]), _v(vs[c]), _v(ns[c]), mat))
        else:
            sys.exit('%s: unknown NFF entity %r' % (path, t))

    aspect = width / height
    hfov = 2 * math.degrees(math.atan(math.tan(math.radians(cam['angle']) / 2) * aspect))
    o = ['#version 3.7;',
         'global_settings { assumed_gamma 1.0 max_trace_level %d adc_bailout 0 ambient_light 0 }' % depth,
         # right = -x: POV is left-handed; this gives the right-handed NFF image.
         'camera { perspective location %s look_at %s sky %s right <-%r,0,0> up <0,1,0> angle %r }'
         % (_v(cam['from']), _v(cam['at']), _v(cam['up']), aspect, hfov),
         'background { color rgb %s }' % _v(bg)]
    default = 1 / math.sqrt(len(lights)) if lights else 1
    for p, col in lights:
        c = col if col else (default, default, default)
        o.append('light_source { %s color rgb %s }' % (_v(p), _v(c)))
    for i, (r, g, b, kd, ks, shine, tr, ior) in enumerate(out_mats):
        mr = mirror[i]
        refl = '%r' % mr[0] if mr[0] == mr[1] == mr[2] else 'rgb %s' % _v(mr)
        phong = _highlight(path, i, (r, g, b), spec[i])
        emission = _emission(path, i, (r, g, b), tr, emit[i])
        o.append('#declare M%d = texture { pigment { rgbt <%r,%r,%r,%r> } '
                 'finish { ambient 0 emission %s diffuse %r phong %s phong_size %r reflection %s } }'
                 % (i, r, g, b, tr, emission, kd, phong, max(shine, 1e-6), refl))
    # Interiors (the ior) belong to objects, not textures.
    for ob in objects:
        head, m, tail = ob.rsplit('@', 2)[0], None, None
        parts = ob.split('@')
        m = int(parts[1][1:])
        tr, ior = out_mats[m][6], out_mats[m][7]
        inside = ' interior { ior %r }' % ior if tr > 0 else ''
        o.append(parts[0] + 'texture { M%d }%s' % (m, inside) + parts[2])
    print('\n'.join(o))


def _highlight(path, i, pigment, ks):
    """POV-Ray's phong for the highlight colour ks: one amount (times the light), or
    with metallic times the pigment's colour too."""
    if ks[0] == ks[1] == ks[2]:
        return '%r' % ks[0]
    # In proportion to the pigment: amount k with metallic, exact.
    k = [ks[c] / pigment[c] for c in range(3) if pigment[c] != 0]
    if k and all(ks[c] == 0 for c in range(3) if pigment[c] == 0) and \
            max(k) - min(k) <= 1e-9 * max(abs(x) for x in k):
        return '%r metallic' % k[0]
    mean = sum(ks) / 3
    sys.stderr.write('%s: material %d: highlight \'#vw Ks %r %r %r\': POV-Ray\'s phong has one '
                     'amount for all channels (or one in proportion to the pigment %r %r %r): '
                     'converted as their mean, %r\n' % ((path, i) + tuple(ks) + tuple(pigment) + (mean,)))
    return '%r' % mean


def _emission(path, i, pigment, tr, ke):
    """POV-Ray's emission for vwalls' Ke: POV scales it by the pigment's colour and by
    (1 - transmit), so it is divided by them; a channel where they are 0 cannot emit."""
    if ke == (0.0, 0.0, 0.0):
        return '0'
    out, lost = [], []
    for c in range(3):
        scale = pigment[c] * (1 - tr)
        if scale != 0:
            out.append(ke[c] / scale)
        else:
            out.append(0.0)
            if ke[c] != 0:
                lost.append('rgb'[c])
    if lost:
        sys.stderr.write('%s: material %d: emission \'#vw Ke %r %r %r\': POV-Ray scales emission '
                         'by the pigment (%r %r %r) and by 1 - transmit (%r), which are 0 in '
                         'channel %s: it emits nothing there\n'
                         % ((path, i) + tuple(ke) + tuple(pigment) + (1 - tr, ', '.join(lost))))
    return 'rgb %s' % _v(out)


def _triangulate(vs):
    """Corner index triples covering the polygon vs (convex or concave, simple): ear
    clipping in the plane of its Newell normal. A corner is an ear when it turns the
    polygon's way and no other corner lies inside its triangle. Where no ear is found
    (a self-intersecting ring) the rest is fanned."""
    n = len(vs)
    nrm = [0.0, 0.0, 0.0]
    for i in range(n):
        p, q = vs[i], vs[(i + 1) % n]
        nrm[0] += (p[1] - q[1]) * (p[2] + q[2])
        nrm[1] += (p[2] - q[2]) * (p[0] + q[0])
        nrm[2] += (p[0] - q[0]) * (p[1] + q[1])
    drop = max(range(3), key=lambda k: abs(nrm[k]))
    u, w = [k for k in range(3) if k != drop]
    pts = [(v[u], v[w]) for v in vs]
    sign = 1 if sum(pts[i][0] * pts[(i + 1) % n][1] - pts[(i + 1) % n][0] * pts[i][1]
                    for i in range(n)) >= 0 else -1

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    def inside(p, a, b, c):
        return (sign * cross(a, b, p) >= 0 and sign * cross(b, c, p) >= 0
                and sign * cross(c, a, p) >= 0)

    ring, tris = list(range(n)), []
    while len(ring) > 3:
        for k in range(len(ring)):
            i, j, l = ring[k - 1], ring[k], ring[(k + 1) % len(ring)]
            a, b, c = pts[i], pts[j], pts[l]
            if sign * cross(a, b, c) <= 0:
                continue  # reflex or straight: not an ear
            if any(inside(pts[m], a, b, c) for m in ring
                   if m not in (i, j, l) and pts[m] not in (a, b, c)):
                continue
            tris.append((i, j, l))
            del ring[k]
            break
        else:
            tris.extend((ring[0], ring[k], ring[k + 1]) for k in range(1, len(ring) - 1))
            return tris
    tris.append(tuple(ring))
    return tris


def _isnum(s):
    try:
        float(s)
        return True
    except ValueError:
        return False


def _v(v):
    return '<%r,%r,%r>' % tuple(v)


if __name__ == '__main__':
    main()
