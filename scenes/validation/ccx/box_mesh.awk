# Structured 20-node hex mesh of the box [0, L] x [-B/2, B/2] x [-H/2, H/2] for ccx, shared by
# make_cantilever_reference.sh and make_slit_reference.sh (see README.md in this folder).
#
# Nodes live on the half-step lattice (I,J,K), I = 0..2nx etc.; a lattice point is a node of
# the C3D20 mesh iff at most one of I,J,K is odd.
#
# Optional slit (crack_i >= 0): the plane x = L * crack_i / nx from the top face z = H/2 down
# to z = -H/2 + H * crack_k / nz, as duplicated nodes. Every node on that plane above the front
# (K > 2 crack_k) gets a twin; the elements on the +x side of the plane use the twins, those on
# the -x side the originals, so the two faces are not joined. Nodes on the front are shared.
#
# Variables: nx ny nz L B H eltype mesh tab [crack_i crack_k]. Writes `mesh` (*NODE, *ELEMENT,
# NSETs NFIX at x = 0 and NTIP at x = L) and `tab` ("id I J K x y z twin": twin 1 for a
# duplicate on the slit's +x face, else 0); prints "nodes elements".
function odd(a) { return a % 2 }
function nid(I, J, K, side) {
    if (side && ((I "," J "," K) in twin)) return twin[I "," J "," K]
    return id[I "," J "," K]
}
function flush_set(name, list, n,   i, line) {
    print "*NSET,NSET=" name > mesh
    line = ""
    for (i = 1; i <= n; i++) {
        line = line list[i] ","
        if (i % 16 == 0 || i == n) { print line > mesh; line = "" }
    }
}
function add_node(I, J, K, is_twin,   x, y, z) {
    n++
    x = L * I / NI; y = -B / 2 + B * J / NJ; z = -H / 2 + H * K / NK
    printf "%d,%.12g,%.12g,%.12g\n", n, x, y, z > mesh
    printf "%d %d %d %d %.12g %.12g %.12g %d\n", n, I, J, K, x, y, z, is_twin > tab
    if (I == 0)  fix[++nfix] = n
    if (I == NI) tip[++ntip] = n
    return n
}
BEGIN {
    if (crack_i == "") crack_i = -1
    NI = 2 * nx; NJ = 2 * ny; NK = 2 * nz
    CI = 2 * crack_i; CK = 2 * crack_k
    print "** structured " nx "x" ny "x" nz " " eltype " mesh, generated" > mesh
    print "*NODE,NSET=NALL" > mesh
    n = 0; nfix = 0; ntip = 0
    for (K = 0; K <= NK; K++) for (J = 0; J <= NJ; J++) for (I = 0; I <= NI; I++) {
        if (odd(I) + odd(J) + odd(K) > 1) continue
        id[I "," J "," K] = add_node(I, J, K, 0)
        if (crack_i >= 0 && I == CI && K > CK) twin[I "," J "," K] = add_node(I, J, K, 1)
    }
    print "*ELEMENT,TYPE=" eltype ",ELSET=EALL" > mesh
    e = 0
    for (k = 0; k < nz; k++) for (j = 0; j < ny; j++) for (i = 0; i < nx; i++) {
        I = 2 * i; J = 2 * j; K = 2 * k
        s = (crack_i >= 0 && i >= crack_i)  # on the slit's +x side: its twins
        # corners (bottom z-, then top z+), counter-clockwise seen from +z
        c[1] = nid(I, J, K, s);     c[2] = nid(I+2, J, K, s)
        c[3] = nid(I+2, J+2, K, s); c[4] = nid(I, J+2, K, s)
        c[5] = nid(I, J, K+2, s);     c[6] = nid(I+2, J, K+2, s)
        c[7] = nid(I+2, J+2, K+2, s); c[8] = nid(I, J+2, K+2, s)
        # mid-edges: 9-12 bottom, 13-16 top, 17-20 vertical
        c[9]  = nid(I+1, J, K, s);   c[10] = nid(I+2, J+1, K, s)
        c[11] = nid(I+1, J+2, K, s); c[12] = nid(I, J+1, K, s)
        c[13] = nid(I+1, J, K+2, s);   c[14] = nid(I+2, J+1, K+2, s)
        c[15] = nid(I+1, J+2, K+2, s); c[16] = nid(I, J+1, K+2, s)
        c[17] = nid(I, J, K+1, s);     c[18] = nid(I+2, J, K+1, s)
        c[19] = nid(I+2, J+2, K+1, s); c[20] = nid(I, J+2, K+1, s)
        e++
        line = e
        for (m = 1; m <= 15; m++) line = line "," c[m]
        print line "," > mesh
        print c[16] "," c[17] "," c[18] "," c[19] "," c[20] > mesh
    }
    flush_set("NFIX", fix, nfix)
    flush_set("NTIP", tip, ntip)
    printf "%d %d\n", n, e
}
