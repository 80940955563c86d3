#!/usr/bin/python3
"""canyon's map tracks read back by independent readers (issue 29).

A short `downtown` walk is simulated and solved by canyon fusion and canyon rtk; `canyon evaluate --kml --gpx` and
`canyon convert SOL.pos --kml --gpx` write the tracks. The GPX files are read with gpxpy and the KML files with
fastkml (Debian's python3-gpxpy and python3-fastkml, not canyon's code), and every epoch of every .pos file must be
there, at its UTC time, position and status; the truth must be beside them. The element order is checked against the
sequences of the GPX 1.1 schema (wptType) and of the KML 2.2 schema (Feature, Placemark), and the values against
their types (GPX fix, lat/lon ranges, KML colours and coordinates). Bad input: a KML path that cannot be written (the
other outputs are kept and listed), a missing and a truncated solution file.

Usage: map_tracks_check.py BUILD_DIR      (exit 0 pass, 1 fail, 77 the readers are not installed)
Runs with Debian's /usr/bin/python3, where scripts/setup.sh installs the two readers.
"""
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

try:
    import gpxpy
    from fastkml import kml as fastkml_kml
except ImportError as e:
    print("SKIP: the independent readers are missing (%s): scripts/setup.sh installs python3-gpxpy and "
          "python3-fastkml" % e)
    sys.exit(77)

GPX_NS = "{http://www.topografix.com/GPX/1/1}"
KML_NS = "{http://www.opengis.net/kml/2.2}"
# GPX 1.1 schema, wptType: the sequence of a trkpt's elements.
WPT_SEQUENCE = ["ele", "time", "magvar", "geoidheight", "name", "cmt", "desc", "src", "link", "sym", "type", "fix",
                "sat", "hdop", "vdop", "pdop", "ageofdgpsdata", "dgpsid", "extensions"]
GPX_FIX = {"none", "2d", "3d", "dgps", "pps"}
# KML 2.2 schema: AbstractFeatureGroup's sequence, then Placemark's geometry.
PLACEMARK_SEQUENCE = ["name", "visibility", "open", "author", "link", "address", "AddressDetails", "phoneNumber",
                      "Snippet", "description", "Camera", "LookAt", "TimeStamp", "TimeSpan", "styleUrl", "Style",
                      "StyleMap", "Region", "ExtendedData", "Point", "LineString", "LinearRing", "Polygon",
                      "MultiGeometry", "Model"]
STATUS = {1: "fixed", 2: "float", 5: "single", 7: "fill-in"}
KML_COLOUR = {"fixed": "ff00ff00", "float": "ff00ffff", "single": "ff0000ff", "fill-in": "ffff0000"}
GPS_MINUS_UTC_S = 18  # 2023 (the scenario's date)
SECONDS_PER_WEEK = 604800
GPS_EPOCH_UNIX_S = 315964800

failures = []


def check(condition, what):
    if not condition:
        failures.append(what)
        print("FAIL: " + what)
    return condition


def run(args, expect=0):
    p = subprocess.run(args, capture_output=True, text=True)
    if p.returncode != expect:
        print("command %s exited %d (expected %d): %s" % (" ".join(args), p.returncode, expect, p.stderr[-600:]))
        sys.exit(1)
    return p


def read_pos(path):
    """The solved epochs of a .pos file: (utc unix time rounded to ms, lat, lon, h, status name, satellites)."""
    epochs = []
    for line in open(path):
        if line.startswith("%") or not line.strip():
            continue
        f = line.split()
        week, tow, lat, lon, h, q, ns = int(f[0]), float(f[1]), float(f[2]), float(f[3]), float(f[4]), int(f[5]), \
            int(f[6])
        if q == 0:
            continue
        utc = GPS_EPOCH_UNIX_S + week * SECONDS_PER_WEEK + tow - GPS_MINUS_UTC_S
        epochs.append((round(utc * 1000), lat, lon, h, STATUS.get(q, "other"), ns))
    return epochs


def local(tag):
    return tag.split("}")[-1]


def in_sequence(children, sequence):
    """Whether the child element names follow the schema's sequence (each known, in order)."""
    positions = [sequence.index(local(c.tag)) if local(c.tag) in sequence else -1 for c in children]
    return all(p >= 0 for p in positions) and positions == sorted(positions)


def check_gpx(path, expected, truth_points):
    """expected: label -> epochs of its .pos file."""
    root = ET.parse(path).getroot()
    check(root.tag == GPX_NS + "gpx" and root.get("version") == "1.1", "%s: root is GPX 1.1" % path)
    names = [local(c.tag) for c in root]
    check(names == sorted(names, key=lambda n: ["metadata", "wpt", "rte", "trk", "extensions"].index(n)),
          "%s: gpx children in the schema's order: %s" % (path, names[:5]))
    for pt in root.iter(GPX_NS + "trkpt"):
        if not in_sequence(list(pt), WPT_SEQUENCE):
            check(False, "%s: trkpt children out of wptType's order: %s" % (path, [local(c.tag) for c in pt]))
            break
        fix = pt.find(GPX_NS + "fix")
        sat = pt.find(GPX_NS + "sat")
        if (fix is not None and fix.text not in GPX_FIX) or (sat is not None and not sat.text.isdigit()) or \
                not (-90 <= float(pt.get("lat")) <= 90 and -180 <= float(pt.get("lon")) < 180):
            check(False, "%s: a trkpt value outside its type: %s" % (path, ET.tostring(pt)[:200]))
            break
    gpx = gpxpy.parse(open(path))
    got = {}
    truth = 0
    for trk in gpx.tracks:
        if trk.name == "truth":
            truth += sum(len(s.points) for s in trk.segments)
            continue
        label, status = trk.name.rsplit(": ", 1)
        check(trk.type == status, "%s: track %s has type %s" % (path, trk.name, trk.type))
        for seg in trk.segments:
            for p in seg.points:
                got.setdefault(label, []).append((round(p.time.timestamp() * 1000), p.latitude, p.longitude,
                                                  p.elevation, status, int(p.satellites)))
    for label, epochs in expected.items():
        mine = sorted(got.get(label, []))
        check(len(mine) == len(epochs), "%s: %s has %d points for %d epochs" % (path, label, len(mine), len(epochs)))
        bad = [(a, b) for a, b in zip(mine, sorted(epochs))
               if a[0] != b[0] or abs(a[1] - b[1]) > 2e-9 or abs(a[2] - b[2]) > 2e-9 or abs(a[3] - b[3]) > 2e-3
               or a[4] != b[4] or a[5] != b[5]]
        check(not bad, "%s: %s: %d points differ from the .pos epochs, first %s" % (path, label, len(bad),
                                                                                    bad[:1]))
    check(truth == truth_points, "%s: truth track has %d points for %d truth rows" % (path, truth, truth_points))


def kml_children(element):
    return list(element.features()) if hasattr(element, "features") else []


def check_kml(path, expected, truth_points):
    root = ET.parse(path).getroot()
    check(root.tag == KML_NS + "kml", "%s: root is KML 2.2" % path)
    for pm in root.iter(KML_NS + "Placemark"):
        if not in_sequence(list(pm), PLACEMARK_SEQUENCE):
            check(False, "%s: Placemark children out of the schema's order: %s" % (path, [local(c.tag) for c in pm]))
            break
    for colour in root.iter(KML_NS + "color"):
        if len(colour.text) != 8 or any(c not in "0123456789abcdef" for c in colour.text):
            check(False, "%s: colour %s is not aabbggrr hex" % (path, colour.text))
            break
    doc = fastkml_kml.KML()
    doc.from_string(open(path, "rb").read())
    document = kml_children(doc)[0]
    styles = {s.id: s for s in document.styles()}
    for status, colour in KML_COLOUR.items():
        icon = [st for st in styles[status].styles() if type(st).__name__ == "IconStyle"]
        check(icon and icon[0].color == colour, "%s: style %s coloured %s" % (path, status, colour))
    folders = {f.name: f for f in kml_children(document)}
    for label, epochs in expected.items():
        points = []
        for pm in kml_children(folders[label]):
            if pm.geometry.geom_type == "Point":
                lon, lat = pm.geometry.x, pm.geometry.y
                when = pm.timeStamp
                status = pm.styleUrl.lstrip("#")
                check(status in styles, "%s: style %s is defined" % (path, status))
                points.append((round(when.timestamp() * 1000), lat, lon, status))
        mine = sorted(points)
        check(len(mine) == len(epochs), "%s: %s has %d points for %d epochs" % (path, label, len(mine), len(epochs)))
        bad = [(a, b) for a, b in zip(mine, sorted(epochs))
               if a[0] != b[0] or abs(a[1] - b[1]) > 2e-9 or abs(a[2] - b[2]) > 2e-9 or a[3] != b[4]]
        check(not bad, "%s: %s: %d points differ from the .pos epochs, first %s" % (path, label, len(bad), bad[:1]))
    if truth_points:
        lines = [pm for pm in kml_children(folders["truth"]) if pm.geometry.geom_type == "LineString"]
        check(lines and len(lines[0].geometry.coords) == truth_points,
              "%s: the truth line has every truth row (%d)" % (path, truth_points))


def main():
    build = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else "build")
    canyon = os.path.join(build, "canyon")
    with tempfile.TemporaryDirectory() as tmp:
        sim = os.path.join(tmp, "sim")
        run([canyon, "simulate", "-q", "--scenario", "downtown", "--seed", "3", "--duration", "90", "--out", sim])
        inputs = ["--rover", sim + "/rover.obs", "--base", sim + "/base.obs", "--nav", sim + "/nav.rnx"]
        fusion, rtk = os.path.join(tmp, "fusion.pos"), os.path.join(tmp, "rtk.pos")
        run([canyon, "process", "-q", "--mode", "fusion", *inputs, "--vio", sim + "/vio.csv", "--timesync",
             sim + "/timesync.csv", "--out", fusion])
        run([canyon, "process", "-q", "--mode", "rtk", *inputs, "--out", rtk])
        expected = {"fusion": read_pos(fusion), "rtk": read_pos(rtk)}
        statuses = {e[4] for epochs in expected.values() for e in epochs}
        check(len(statuses) >= 3, "the walk gives at least three statuses to draw: %s" % sorted(statuses))
        truth_rows = sum(1 for line in open(sim + "/truth.csv") if line[0].isdigit())
        kml, gpx = os.path.join(tmp, "out", "tracks.kml"), os.path.join(tmp, "out", "tracks.gpx")
        run([canyon, "evaluate", "-q", "--truth", sim + "/truth.csv", "--rover", sim + "/rover.obs", "--solution",
             fusion, "--solution", rtk, "--label", "fusion", "--label", "rtk", "--kml", kml, "--gpx", gpx])
        check_gpx(gpx, expected, truth_rows)
        check_kml(kml, expected, truth_rows)
        one_kml, one_gpx = os.path.join(tmp, "one.kml"), os.path.join(tmp, "one.gpx")
        run([canyon, "convert", "-q", fusion, "--kml", one_kml, "--gpx", one_gpx])
        check_gpx(one_gpx, {"fusion": expected["fusion"]}, 0)
        check_kml(one_kml, {"fusion": expected["fusion"]}, 0)
        print("tracks: %s" % ", ".join("%s %d epochs" % (k, len(v)) for k, v in expected.items()) +
              "; statuses %s; truth %d rows" % (sorted(statuses), truth_rows))

        # Bad input: a KML path that cannot be written keeps what was written before it and says so.
        json_out = os.path.join(tmp, "kept.json")
        p = run([canyon, "evaluate", "-q", "--truth", sim + "/truth.csv", "--solution", fusion, "--json", json_out,
                 "--kml", "/dev/null/tracks.kml"], expect=1)
        check("/dev/null/tracks.kml" in p.stderr and "kept" in p.stderr and os.path.getsize(json_out) > 0,
              "an unwritable KML path is named and the JSON kept: %s" % p.stderr.strip())
        p = run([canyon, "convert", os.path.join(tmp, "missing.pos"), "--gpx", one_gpx], expect=1)
        check("missing.pos" in p.stderr, "a missing solution file is named: %s" % p.stderr.strip())
        cut = os.path.join(tmp, "cut.pos")
        lines = open(fusion).read().splitlines()
        with open(cut, "w") as out:
            out.write("\n".join(lines[:-1]) + "\n" + lines[-1][:30] + "\n")
        p = run([canyon, "convert", cut, "--kml", one_kml], expect=1)
        check("cut.pos" in p.stderr and str(len(lines)) in p.stderr,
              "a truncated solution file is named with its line %d: %s" % (len(lines), p.stderr.strip()))
    print("map tracks: %s" % ("PASS" if not failures else "%d failures" % len(failures)))
    return 0 if not failures else 1


if __name__ == "__main__":
    sys.exit(main())
