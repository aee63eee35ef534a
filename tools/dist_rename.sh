#!/bin/sh
# The distances' fields moved from the world's model, state and cache (core.h: w->m,
# w->s, w->k) into struct wb_distances (distance.h), pointed to by w->dist. Re-applies the
# mechanical part of that change to C sources written against the old layout:
#
#   sh tools/dist_rename.sh FILE...           every X->m.F, X->s.F, X->k.F
#   sh tools/dist_rename.sh --alias FILE...   also m->F, s->F, k->F (m = &w->m, s = &w->s,
#                                             k = &w->k): only for files where those names
#                                             are the world's parts
#
# A read through the world, w->m.d_ij, becomes wb__dist(w->dist)->ij: wb__dist (distance.h)
# gives an empty struct when the world has no distances yet (w->dist == NULL), so reads
# need no check. Through an alias, m->d_ij becomes ds->ij: declare
#     const wb_distances *ds = wb__dist(w->dist);      (reading)
#     wb_distances *ds = w->dist;                (writing: only once one exists)
# where the compiler says ds is undeclared, and drop the m, s, k left unused. A write
# through wb__dist(w->dist) does not compile (it is const): guard it with w->dist.
# Fields the world keeps (not renamed): k.dx, k.ncount (per-particle Jacobi scratch),
# k.h_last, k.projections, m.topology_dirty, m.w_gen.
set -e
alias=0
if [ "$1" = "--alias" ]; then alias=1; shift; fi
ALIAS=$alias perl -pi -e '
BEGIN {
    %M = (nd => "n", cap_d => "cap", nd_live => "nlive", d_ij => "ij", d_alpha => "alpha",
          d_beta => "beta", d_yield => "yield", d_creep => "creep", d_break => "break_strain",
          d_bforce => "bforce", d_gen => "gen", d_free => "free_slots", nfree => "nfree");
    %S = (d_rest => "rest", d_broken => "broken");
    %K = map { $_ => $_ } qw(ns ncolours colour_start serial_start split_start ncomp comp_start
          s_nsp s_a s_b s_rest s_alpha s_beta s_lambda s_jac s_wa s_wc s_at s_oa s_oc s_ok
          s_backed s_backed_vt s_at_h s_slot slot_pack any_damping s_lambda_stale
          any_frame_end s_w_gen breaks nbreaks cap_breaks);
    $m = join "|", sort { length $b <=> length $a } keys %M;
    $s = join "|", sort { length $b <=> length $a } keys %S;
    $k = join "|", sort { length $b <=> length $a } keys %K;
}
s/\b(\w+)->m\.($m)\b/wb__dist($1->dist)->$M{$2}/g;
s/\b(\w+)->s\.($s)\b/wb__dist($1->dist)->$S{$2}/g;
s/\b(\w+)->k\.($k)\b/wb__dist($1->dist)->$K{$2}/g;
if ($ENV{ALIAS}) {
    s/(?<![\w.>])m->($m)\b/ds->$M{$1}/g;
    s/(?<![\w.>])s->($s)\b/ds->$S{$1}/g;
    s/(?<![\w.>])k->($k)\b/ds->$K{$1}/g;
}
' "$@"
