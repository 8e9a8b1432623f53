# eq16.awk: the error of one posedrop column against the paper's physical
# tests: eq. (16), e = 100 sum_i p_i |a_i - p_i| with p the measured and a the
# estimated probabilities, and the total variation 50 sum |a_i - p_i| beside it.
#
#   awk -F, -v part=NAME -v column=p_qs -f scripts/eq16.awk PAPER_TABLES.csv GROUPED.csv
#
# GROUPED.csv is posedrop --group output. Its classes are matched to the
# paper's poses by rank of QS on both sides (the column the parts were fitted
# on; the paper numbers its poses by physical frequency);
# mass on classes beyond the paper's count counts in the total variation only.
# Prints "e16 tv".
FNR == 1 { for (i = 1; i <= NF; i++) col[FILENAME, $i] = i; next }
FILENAME == ARGV[1] {
    if ($col[FILENAME, "part"] == part) {
        n++
        phys[n] = $col[FILENAME, "p_physical"] / 100
        pqsv[n] = $col[FILENAME, "p_qs"] / 100
    }
    next
}
{ k++; qs[k] = $col[FILENAME, "p_qs"]; a[k] = $col[FILENAME, column] }
END {
    # The paper numbers its poses by physical frequency: rank both sides by QS.
    for (i = 1; i <= n; i++) prank[i] = i
    for (i = 1; i <= n; i++) for (j = i + 1; j <= n; j++)
        if (pqsv[prank[j]] > pqsv[prank[i]]) { t = prank[i]; prank[i] = prank[j]; prank[j] = t }
    for (i = 1; i <= k; i++) order[i] = i
    for (i = 1; i <= k; i++) for (j = i + 1; j <= k; j++)
        if (qs[order[j]] > qs[order[i]]) { t = order[i]; order[i] = order[j]; order[j] = t }
    e = 0; tv = 0
    for (r = 1; r <= (k > n ? k : n); r++) {
        est = r <= k ? a[order[r]] : 0
        ph = r <= n ? phys[prank[r]] : 0
        e += ph * (est > ph ? est - ph : ph - est)
        tv += est > ph ? est - ph : ph - est
    }
    printf "%.4f %.4f\n", 100 * e, 50 * tv
}
