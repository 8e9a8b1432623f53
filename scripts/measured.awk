# measured.awk: the paper's physical column of one part in posedrop's class
# numbering, as a file --measured and posedrop fit read (pose,count). The
# paper prints percentages to 0.1 of its trials, which times n are not whole
# drops (13.8% of 545 is 75.2) and a pose,p,n file of them is refused; each
# to the nearest drop is the count the paper rounded.
#
#   awk -F, -v part=NAME -v tag=SCRIPT -f scripts/measured.awk PAPER_TABLES.csv GROUPED.csv
#
# GROUPED.csv is posedrop --group output; its classes are paired with the
# paper's poses by rank of QS on both sides, as scripts/eq16.awk pairs them.
FNR == 1 { delete col; for (i = 1; i <= NF; i++) col[$i] = i; next }
FILENAME == ARGV[1] {
    if ($col["part"] == part) {
        n++; phys[n] = $col["p_physical"] / 100; pqs[n] = $col["p_qs"]; trials = $col["physical_trials"]
    }
    next
}
{ k++; qs[k] = $col["p_qs"]; num[k] = $col["pose"] }
END {
    for (i = 1; i <= n; i++) pr[i] = i
    for (i = 1; i <= n; i++) for (j = i + 1; j <= n; j++)
        if (pqs[pr[j]] > pqs[pr[i]]) { t = pr[i]; pr[i] = pr[j]; pr[j] = t }
    for (i = 1; i <= k; i++) ord[i] = i
    for (i = 1; i <= k; i++) for (j = i + 1; j <= k; j++)
        if (qs[ord[j]] > qs[ord[i]]) { t = ord[i]; ord[i] = ord[j]; ord[j] = t }
    if (n > k) { print tag ": the paper has more poses than posedrop classes" > "/dev/stderr"; exit 1 }
    print "pose,count"
    for (r = 1; r <= n; r++) printf "%d,%d\n", num[ord[r]], int(phys[pr[r]] * trials + 0.5)
}
