#!/usr/bin/env python3
"""nff2pov.py - converts an NFF scene to POV-Ray 3.7 SDL for bench/raytrace.sh, matching
vwalls render's conventions: no ambient, diffuse = colour * Kd, Phong highlight Ks with
exponent Shine, mirror reflection Ks, transmission T with ior, lights without colour at
1/sqrt(#lights), linear output (assumed_gamma 1), the same camera (NFF angle is the
vertical field of view; POV's is horizontal) and a right-handed image.

usage: nff2pov.py SCENE.nff WIDTH HEIGHT DEPTH > SCENE.pov
"""
import math
import sys


def main():
    path, width, height, depth = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
    # NFF is read by tokens, not lines; '#' starts a comment to the end of the line.
    toks = []
    with open(path) as f:
        for line in f:
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
    lights, objects, out_mats = [], [], []
    mat = None
    while pos < len(toks):
        t = nxt()
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
            mat = len(out_mats)
            out_mats.append((r, g, b, kd, ks, shine, tr, ior))
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
            for j in range(1, n - 1):
                if t == 'pp':
                    objects.append('smooth_triangle { %s, %s, %s, %s, %s, %s @M%d@ }' % (
                        _v(vs[0]), _v(ns[0]), _v(vs[j]), _v(ns[j]), _v(vs[j + 1]), _v(ns[j + 1]), mat))
                else:
                    objects.append('triangle { %s, %s, %s @M%d@ }' % (
                        _v(vs[0]), _v(vs[j]), _v(vs[j + 1]), mat))
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
        o.append('#declare M%d = texture { pigment { rgbt <%r,%r,%r,%r> } '
                 'finish { ambient 0 emission 0 diffuse %r phong %r phong_size %r reflection %r } }'
                 % (i, r, g, b, tr, kd, ks, max(shine, 1e-6), ks))
    # Interiors (the ior) belong to objects, not textures.
    for ob in objects:
        head, m, tail = ob.rsplit('@', 2)[0], None, None
        parts = ob.split('@')
        m = int(parts[1][1:])
        tr, ior = out_mats[m][6], out_mats[m][7]
        inside = ' interior { ior %r }' % ior if tr > 0 else ''
        o.append(parts[0] + 'texture { M%d }%s' % (m, inside) + parts[2])
    print('\n'.join(o))


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
