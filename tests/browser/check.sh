#!/usr/bin/env bash
# check.sh: the pictures in a real browser and a real SVG renderer
# (make check-browser; .ci/run calls it).
#
# Renders the insulator cap's report (posedrop --report, 2000 drops) in
# headless Chromium and checks that the page logs nothing to the console,
# that its screenshot is not blank, and that its DOM holds one gallery panel
# per pose of the CSV, each labelled "Pose N"; that the report and the SVGs
# are well-formed XML (xmllint) and the report loads nothing from elsewhere;
# and renders each SVG with rsvg-convert, checking its size against the
# file's own width and height and that it is not blank. Negative controls
# first show that each check can fail: a page that logs to the console, and
# a blank image. The report at 34 and 98 poses: every picture drawn at 0.8
# of its size or more in a 1280 px window (text readable). Last line "N passed, N failed"; exit status 1 on a failure.
set -u
cd "$(dirname "$0")/../.."
scripts/install-deps.sh browser || exit 1
bin=${POSEDROP:-build/opt/posedrop}
[ -x "$bin" ] || { echo "check-browser: $bin not built" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
. tests/support/check.sh

# Chromium as root needs --no-sandbox; its own profile in tmp; a bound on
# time so a hung browser fails the test instead of hanging it.
browse() { # OUTPUT-FLAG URL LOG
    timeout 180 chromium --headless --no-sandbox --disable-gpu --hide-scrollbars \
        --user-data-dir="$tmp/profile" --enable-logging=stderr --v=0 \
        --window-size=1280,1600 "$1" "$2" 2> "$3"
}
console_lines() { grep -c ':CONSOLE' "$1"; }

# Negative controls: the console check sees a logging page, the image check
# a blank one.
printf '<!DOCTYPE html><html><head><title>x</title></head><body><p>x</p><script>console.error("posedrop-control")</script></body></html>\n' > "$tmp/control.html"
browse --dump-dom "file://$tmp/control.html" "$tmp/control.log" > /dev/null
check '[ "$(console_lines "$tmp/control.log")" -ge 1 ]' "the console check does not see a page's console.error"
printf '<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="40" height="30"><rect width="40" height="30" fill="#ffffff"/></svg>\n' > "$tmp/blank.svg"
rsvg-convert -o "$tmp/blank.png" "$tmp/blank.svg"
read -r w h cov col < <(python3 tests/browser/pngstat.py "$tmp/blank.png")
check '[ "$w" = 40 ] && [ "$h" = 30 ] && [ "$cov" = 0.000000 ]' "a blank image is not seen as blank ($w $h $cov)"

# The cap's report and figures.
"$bin" -n 2000 --report "$tmp/cap.html" --svg "$tmp/gallery.svg" --chart "$tmp/chart.svg" \
    --sphere "$tmp/sphere.svg" parts/cap.off > "$tmp/cap.csv" 2> "$tmp/cap.err"
check '[ $? -eq 0 ]' "posedrop --report failed: $(cat "$tmp/cap.err")"
nposes=$(($(wc -l < "$tmp/cap.csv") - 1))
check '[ "$nposes" -ge 2 ]' "the cap's CSV has $nposes poses"

for f in cap.html gallery.svg chart.svg sphere.svg; do
    check 'xmllint --noout --nonet "$tmp/$f" 2> "$tmp/xml.err"' "$f is not well-formed XML: $(head -3 "$tmp/xml.err" 2>/dev/null)"
done
check '! grep -Eqi "<script|<link|<img|<iframe|src=|url\(|@import" "$tmp/cap.html"' \
    "the report loads or runs something: $(grep -Eoi '<script|<link|<img|<iframe|src=|url\(|@import' "$tmp/cap.html" | head -3)"

browse --dump-dom "file://$tmp/cap.html" "$tmp/dom.log" > "$tmp/dom.html"
check '[ "$(console_lines "$tmp/dom.log")" -eq 0 ]' "the report logs to the console: $(grep ':CONSOLE' "$tmp/dom.log" | head -3)"
gallery=$(sed -n '/<section id="gallery">/,/<\/section>/p' "$tmp/dom.html")
panels=$(printf '%s' "$gallery" | grep -o 'class="panel"' | wc -l)
check '[ "$panels" -eq "$nposes" ]' "the rendered gallery has $panels panels for $nposes poses"
missing=""
for i in $(seq 1 "$nposes"); do
    printf '%s' "$gallery" | grep -q ">Pose $i<" || missing="$missing $i"
done
check '[ -z "$missing" ]' "no label in the rendered gallery for poses:$missing"

browse --screenshot="$tmp/cap.png" "file://$tmp/cap.html" "$tmp/shot.log" > /dev/null
check '[ "$(console_lines "$tmp/shot.log")" -eq 0 ]' "the report logs to the console when drawn"
read -r w h cov col < <(python3 tests/browser/pngstat.py "$tmp/cap.png" || echo 0 0 0 0)
# Text, a table and the gallery's first row in the window: far from blank
# (a white page covers 0, and a page of text only about 0.05).
check 'awk -v c="$cov" -v n="$col" "BEGIN { exit !(c > 0.08 && n > 50) }"' \
    "the screenshot looks blank: ${w}x$h, $cov of the pixels drawn, $col colours"

for f in gallery chart sphere; do
    rsvg-convert -o "$tmp/$f.png" "$tmp/$f.svg" 2> "$tmp/rsvg.err"
    check '[ $? -eq 0 ]' "rsvg-convert failed on $f.svg: $(cat "$tmp/rsvg.err")"
    sw=$(sed -n 's/^<svg [^>]*width="\([0-9.]*\)".*/\1/p' "$tmp/$f.svg" | head -1)
    sh=$(sed -n 's/^<svg [^>]*height="\([0-9.]*\)".*/\1/p' "$tmp/$f.svg" | head -1)
    read -r w h cov col < <(python3 tests/browser/pngstat.py "$tmp/$f.png" || echo 0 0 0 0)
    check 'awk -v a="$w" -v b="$sw" -v c="$h" -v d="$sh" "BEGIN { exit !(a == int(b + 0.5) && c == int(d + 0.5)) }"' \
        "$f.png is ${w}x$h, the SVG says ${sw}x$sh"
    check 'awk -v c="$cov" -v n="$col" "BEGIN { exit !(c > 0.05 && n > 20) }"' \
        "$f.png looks blank: $cov of the pixels drawn, $col colours"
done
# The report at 34 and 98 poses (the cap and the insulator cap, not
# grouped) in a laptop's 1280 px window: every picture drawn at 0.8 of its
# size or more, so that its smallest text (11 px) is at least 8.8 px on the
# screen (a 34-pose chart in one row was scaled to 0.34). A copy of the page
# gets a script that measures each SVG's drawn width against its own, into
# the DOM that --dump-dom prints.
measure='<script>var o=[];document.querySelectorAll("section svg").forEach(function(s){o.push(s.closest("section").id+" "+(s.getBoundingClientRect().width/s.width.baseVal.value).toFixed(3))});var p=document.createElement("pre");p.id="measured";p.textContent=o.join(";");document.body.appendChild(p)</script>'
for case in "cap 34" "insulator_cap 98"; do
    read -r part want <<< "$case"
    "$bin" -n 200 --report "$tmp/$part.r.html" "parts/$part.off" > "$tmp/$part.r.csv" 2> /dev/null
    k=$(($(wc -l < "$tmp/$part.r.csv") - 1))
    check '[ "$k" -eq "$want" ]' "parts/$part.off has $k poses, not $want"
    sed "s|</body>|$measure</body>|" "$tmp/$part.r.html" > "$tmp/$part.m.html"
    browse --dump-dom "file://$tmp/$part.m.html" "$tmp/$part.m.log" > "$tmp/$part.m.dom"
    scales=$(sed -n 's|.*<pre id="measured">\([^<]*\)</pre>.*|\1|p' "$tmp/$part.m.dom")
    check '[ "$(printf "%s" "$scales" | tr ";" "\n" | grep -c "^chart ")" -eq 1 ]' \
        "$part: no chart measured in the rendered report: '$scales'"
    small=$(printf '%s' "$scales" | tr ';' '\n' | awk '$2 < 0.8')
    check '[ -z "$small" ]' "$part, $want poses: pictures drawn below 0.8 of their size: $small"
done

[ -n "${KEEP:-}" ] && cp "$tmp"/*.png "$tmp"/*.html "$tmp"/*.svg "$KEEP"/ 2>/dev/null
echo "check-browser: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
