# oblique.awk - an oblique line of 400 spheres from one corner of the box to the other,
# seen from the side: load that a grid of walls cuts badly and a rotated frame follows.
# The scene of bench/balance.sh and tests/balance/slowest.sh. usage: awk -f oblique.awk
BEGIN {
  print "v\nfrom 22 -14 8\nat 5 5 5\nup 0 0 1\nangle 40\nhither 0.01\nresolution 256 256";
  print "b 0.1 0.1 0.1\nl 30 -20 30\nl -10 -10 20";
  srand(7);
  for (i = 0; i < 400; i++) {
    t = i / 399; j = 0.25 * (rand() - 0.5); k = 0.25 * (rand() - 0.5);
    printf "f %.2f %.2f %.2f 0.8 0.2 10 0 1\n", 0.3 + 0.7 * t, 0.4, 1 - 0.7 * t;
    printf "s %.4f %.4f %.4f 0.08\n", 1 + 8 * t + j, 1 + 8 * t + k, 1 + 8 * t + j - k;
  }
}
