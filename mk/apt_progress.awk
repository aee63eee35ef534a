# mk/apt_progress.awk: apt-get's progress for `make deps`, read from its status lines
# (apt-get -o APT::Status-Fd=1: "dlstatus:N:PERCENT:TEXT", "pmstatus:PKG:PERCENT:TEXT");
# every other line is only in the log (tee'd before this). tty=1: one line rewritten in
# place; else a line each 10% of a phase, so that a CI log shows progress too.
BEGIN { FS = ":"; shown = 0 }
/^(dl|pm)status:/ {
    pct = int($3 + 0); msg = $4
    for (i = 5; i <= NF; i++) msg = msg ":" $i
    phase = ($1 == "dlstatus") ? "downloading" : "installing"
    if (tty) {
        printf "\r\033[K  %s [%3d%%] %s", phase, pct, substr(msg, 1, 60)
        shown = 1
    } else {
        key = phase int(pct / 10)
        if (key != last) { printf "  %s [%3d%%] %s\n", phase, pct, msg; last = key }
    }
    fflush()
}
END { if (shown) printf "\r\033[K" }
