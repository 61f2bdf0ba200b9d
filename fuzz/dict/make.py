#!/usr/bin/env python3
"""Writes the fuzz dictionaries (libFuzzer's format: one quoted entry a
line, \\xNN escapes). Run from fuzz/dict: python3 make.py"""

lang = """module Axiom: axiom: produce nproduce interpretation: decomposition: homomorphism:
Start: StartEach: EndEach: End: group endgroup UseGroup CurrentGroup StepNo Forward Backward IsForward Stop
ignore: consider: angle: #define #include #undef #ifdef #ifndef #if #endif #else #elif #pragma <lpfgall.h> <math.h> <stdlib.h> <lintrfc.h>
int float double bool char long unsigned V2f V2d V3f V3d struct typedef const true false
if else while do for break continue return
InLeftContext InRightContext InNewLeftContext InNewRightContext
SB EB SP PP EP F f G g Left Right Up Down RollL RollR TurnAround MoveTo2f MoveTo3f LineTo2f LineTo3f Line2f Line3f LineRel2f LineRel3f
MoveTo LineTo Cut SetColor IncColor DecColor SetWidth Circle Sphere Circle0 CircleB GetPos GetHead GetLeft GetUp Label Surface
Length Normalized Normalize sqrt sin cos tan asin acos atan atan2 exp log pow fabs abs floor ceil fmod fmin fmax min max hypot ran round trunc
PI M_PI
ggroup propensity GillespieTime SeedGillespie ResetGillespie sran rand srand RAND_MAX drand48 srand48 lrand48 random srandom
defined #error 1.f 1e-3f .5f 0x1F 017 10UL 3u
switch case default class public: private: :: 'a' '\\n' '\\0' '\\'' <string.h> <memory.h> <cstdlib>""".split() + ["derivation length:", "ring L-system:", "maximum depth:", "produce;"]
punct = ["<", ">", "<<", ">>", "->", "-->", ":", ";", ",", "(", ")", "{", "}", "[", "]", "?", "==", "!=", "<=", ">=", "&&", "||", "!",
         "+=", "-=", "*=", "/=", "%=", "++", "--", "=", "+", "-", "*", "/", "%", "^", "&", "|", ".", "'", "\"", "//", "/*", "*/", "\\", "#",
         "1e308", "-1", "0.5", "2147483648", "9223372036854775807", "1e-320", "0x10", "\n"]
curve_snippets = ["module P(V2f);", "Axiom: P(v1) P(v2);", "derivation length: 3;", "ring L-system: 1;",
                  "P(vl) < P(v) > P(vr) : { produce P(v) P(v); }", "P(v) -> P(v) P(v)", "V2f v1(0, 0), v2(1, 1);",
                  "#define N 4", "#define M(x) ((x)+(x))", "#if N > 2\n", "#ifdef N\n", "#else\n", "#endif\n",
                  "#if defined(N) && !defined M\n", "ggroup 1:", "propensity 1 produce P(v);", "maximum depth: 2;", "Start: { }", "group 1:",
                  "struct S { int a; float b; };",
                  "switch (n) { case 1: break; case 'a': default: continue; }",
                  "struct L { enum { A, B } k; float w; L() : w(1) {} L(float x) { w = x; } float a() const { return w; } };",
                  "L::A", "l.a()", "typedef struct S T;", "for (int i = 0; i < 3; i++) { }", "x ? y : z", "(float) 1"]
surface = """mesh: blocks: dual bisection quadrisection define init: F(f) V(v E(e F^2 F^3 F^4 E^3 E^4 || | ^
l( c step valence( boundary( new( block( center( centre( transversal( avg( sum( count( ring( boundary_ring( verts( tail( head( bnext( bprev( pos(
where in interior boundary lone( match_blocks adaptive adaptive: incremental area( length( angle( refined(
sharp( sharpness( creases( crease_ring( crease_weight(""".split() + ["derivation length:"]
surface_snippets = ['mesh: "cube.obj";', "F(f) -> V(v = avg(f)) || E^3 F^3;", "E(e; l(e) < c) || F^2 -> E || F^2;",
                    "E(e) | F^2 -> V(v = avg(e)) || E^4 F^4;", "E(e) | F -> V || E^3 F^2;", "V(v; l(v) < c) -> V(v = v);",
                    "define a(n) = 1.0/n;", "sum(w in ring(v) where l(w) < c)", "V(v) | boundary -> V(v = v);", "blocks: dual;",
                    "init: F(f) -> V || E^3 F^3;", "init: match_blocks;", "init: E(e; lone(e)) | F -> V(v = avg(e)) || E^3 F^2;",
                    "blocks: bisection;", "adaptive;"]
mesh = ["v ", "vt ", "vn ", "vp ", "f ", "l ", "p ", "o ", "g ", "s ", "s off", "usemtl ", "mtllib ", "#", "/", "//", "-1", "1/1/1", "1//1",
        "OFF", "COFF", "NOFF", "STOFF", "4OFF", "nOFF", "OFF BINARY",
        "ply", "format ascii 1.0", "format binary_little_endian 1.0", "format binary_big_endian 1.0", "comment ", "obj_info ",
        "element vertex ", "element face ", "element edge ", "property float x", "property double y", "property float z",
        "property list uchar int vertex_indices", "property list uchar uint vertex_index", "property list int int vertex_indices",
        "char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8", "uint8", "int16", "uint16", "int32", "uint32",
        "float32", "float64", "end_header\n", "nan", "inf", "1e309", "4294967295", "18446744073709551615", "\n", "\r\n", " ", "\t",
        "\x00\x00\x80\x3f", "\x03", "\x04", "\xff\xff\xff\xff"]
contour = ["x,y", "x y", "#", "//", ",", ";", " ", "\n", "nan", "inf", "1e308", "-1e308", "1e-308", "0", "-0",
           "<svg", "</svg>", "<svg xmlns=\"http://www.w3.org/2000/svg\">", "<polygon", "<polyline", "<path", "<g>", "</g>", "/>",
           "points=\"", "d=\"", "transform=", "viewBox=", "M", "m", "L", "l", "H", "h", "V", "v", "Z", "z", "C", "Q", "A",
           "<?xml version=\"1.0\"?>", "<!DOCTYPE svg [<!ENTITY a \"1 2\">]>", "&a;", "<![CDATA[", "]]>", "<!--", "-->",
           "\x89PNG\r\n\x1a\n", "IHDR", "IDAT", "IEND", "PLTE", "tRNS", "gAMA", "\x00\x00\x00\x0d",
           "\x08\x06\x00\x00\x00", "\x08\x00\x00\x00\x00", "\x08\x03\x00\x00\x00"]
details = ['"format"', '"subgram-details"', '"version"', '"scheme"', '"builtin:chaikin"', '"builtin:chaikin-open"', '"closed"',
           '"coarse_points"', '"levels"', '"shift"', '"details"', '"dropped"', "null", "true", "false", "[", "]", "{", "}", ":", ",",
           "1e308", "-1e308", "18446744073709551615", "4294967295", "0", "6", "[0.5,0.5]"]


vv = """mesh vertex edge Step: Start: End: forall in add to remove from merge with synchronize make nb_of erase replace splice after before
is valence any nextto prevto null boundary( size( check( $pos $ ' StepNo() V3d( .x .y .z""".split()
vv_snippets = ["mesh S;", "mesh NV;", "vertex x;", "vertex float g = 1;", "edge int w;", "mesh int n;", "(p, q)$w", "mesh$n",
               "forall p in S { }", "forall q in 'p { }", "add x to NV;", "merge S with NV;", "synchronize S;",
               "make {p, null, q} nb_of x;", "replace q with x in p;", "splice x after q in p;", "erase q from p;",
               "x$pos = 0.5 * ('p$pos + 'q$pos);", "if (p < q)", "nextto q in 'p", "prevto x in p", "any in x", "valence 'p",
               "void f(vertex p, vertex q) { }", "Step: { }"]

def esc(s):
    return ''.join('\\x%02x' % ord(c) if c in '"\\' or ord(c) < 32 or ord(c) >= 127 else c for c in s)


def write(name, header, toks):
    seen = []
    for t in toks:
        if t not in seen:
            seen.append(t)
    with open(name + '.dict', 'w') as f:
        f.write('# ' + header + ' (written by make.py)\n')
        f.write(''.join('"%s"\n' % esc(t) for t in seen))


write('lsys_check', '.lsys curve L-systems, surface grammars and vv programs: keywords, directives, punctuation, lpfg modules',
      lang + punct + curve_snippets + surface + surface_snippets + vv + vv_snippets)
write('lsys_derive', 'curve L-systems: keywords, directives, punctuation, lpfg modules and turtle commands',
      lang + punct + curve_snippets)
write('surface_run', 'surface grammars: directives, rule forms, host built-ins, the shared expression language',
      surface + surface_snippets + punct + "int float bool if else sqrt cos sin pow fabs PI #define".split())
write('vv_run', 'vv programs: the algebra statements and built-ins, properties, the shared expression language',
      vv + vv_snippets + punct + "int float double bool if else while for return sqrt cos sin pow PI".split())
shape = """--> ~> \xe2\x87\x9d axiom: attr define NIL epsilon split Split psplit Repeat comp Comp Subdivide f e v x y z X Y Z
t translate r rotate s scale extrude i insert primitiveCube primitiveCylinder primitiveSphere color colour set lot polygon
top bottom front back left right side vertical horizontal all smoothingGroup scope.sx scope.sy scope.sz scope.tx scope.ty scope.tz
split.index split.total comp.index comp.total shape.depth shape.faces ran""".split()
shape_snippets = ['axiom: lot(20, 12) Lot\n', 'Lot --> extrude(9) Mass\n', 'Mass --> comp(f) { top : Roof | side : Facade | bottom : NIL }\n',
                  'Facade --> split(y) { ~3 : Floor }*\n', 'split(x) { 2 : A | \'0.3 : B | ~1 : C }', 'psplit(x, 1, 0) { ~1 : A | ~1 : B | ~1 : C }',
                  'Subdivide(2) { Done }', 'Subdivide(1, "loop") { S }', 'Subdivide(1, "catmull-clark") { S }', 'i("box")', 'i("sphere")',
                  'i("cylinder")', 's(1, 2, 3)', 't(1, 0, 0)', 'r(0, 45, 0)', 'set(smoothingGroup, "g")', 'attr h = 3;', '1 : A : h > 1; ~> B : 0.5\n',
                  '[ ', ' ]', '{ ', ' }', ' | ', ' : ', '*', '\n  ', 'polygon(0, 0, 4, 0, 0, 4)', 'Split(X, 2, ~1) { A | B }', 'Repeat(X, 2) { B }']
write('shape_derive', 'shape grammars: arrows, operations, selectors, scope identifiers, rule forms',
      shape + shape_snippets + punct + "int float bool sqrt cos sin pow PI #define 1e308 1e15 1e-300 0.0/0.0".split())
write('mesh_read', 'OBJ, OFF and PLY keywords, types and numbers', mesh)
write('contour_reverse', 'contours: point lists, SVG elements and path commands, PNG signature and chunk names', contour)
write('details_reconstruct', 'details files (JSON): keys, values, extreme numbers', details)
model = ["funcgalleryver 1 1\n", "contourgalleryver 1 1\n", "timeEdit 1 2\n", "fver 1 1\n", "cver 1 3\n", "cver 1 2\n", "cver 1 1\n",
         "items: ", "name: ", "samples: ", "flip: off\n", "points: ", "type: ", "or", "cr", "oe", "ce", "open", "closed",
         "start: ", "end: ", "color: ", "startLabel: ", "endLabel: ", "timelineFunceditFileStart:\n", "timelineFunceditFileEnd:\n",
         "background: ", "backgroundXY: ", "markers: ", "#define ", "CONTACT POINT X: ", "END POINT X: ", "HEADING X: ", "UP X: ",
         " Y: ", " Z: ", "SIZE: ", "TOP COLOR: 0 DIFFUSE: 0.00 BOTTOM COLOR: 0 DIFFUSE: 0.00\n", "AL: ~ A: ~ AR: ~\n",
         "L: ~ R: ~\n", "BL: ~ B: ~ BR: ~\n", "surface: ", "light: ", "V: ", "A: ", "D: ", "line style: ", "cylinder", "pixel",
         "render mode: ", "first frame: ", "//", "/*", "*/", "0.000000 0.000000\n", "1.000000 1.000000\n", "1 2 3 1\n",
         "nan", "inf", "1e308", "-1", "0", "3", "1000000", "\n", " "]
write('model_files', 'lpfg model files: function, contour, timeline, parameter, surface, view and animation keywords', model)
serve = ["GET ", "POST ", "PUT ", "OPTIONS ", "HEAD ", "/", "/app.js", "/app.css", "/api/source", "/api/render", "/api/save", "?",
         " HTTP/1.1\r\n", " HTTP/1.0\r\n", " HTTP/2.0\r\n", "\r\n", "\r\n\r\n", "\n", ": ", " ", "\t",
         "Host: ", "Origin: ", "Content-Type: ", "Content-Length: ", "Content-Length: $LEN\r\n", "X-Subgram-Token: ",
         "X-Subgram-Token: $TOKEN\r\n", "Sec-Fetch-Site: ", "Expect: 100-continue\r\n", "Transfer-Encoding: chunked\r\n",
         "Connection: close\r\n", "127.0.0.1:$PORT", "localhost:$PORT", "LOCALHOST:$PORT", "127.0.0.1", "localhost", "evil.example",
         ":$PORT", "$PORT", "$TOKEN", "$LEN", "http://127.0.0.1:$PORT", "http://localhost:$PORT", "http://evil.example", "null",
         "same-origin", "same-site", "cross-site", "none", "application/json", "application/json; charset=utf-8", "text/plain",
         '{"text": "', '"}', '"steps": ', '"defines": ["', '"]', "{", "}", ",", "0", "3", "4194305", "18446744073709551616", "-1",
         "Axiom: F;", "F -> F+F", "derivation length: 9;", "mesh: \"/dev/null\";"]
write('serve_request', 'subgram serve requests: methods, routes, headers, hosts, origins, content types; $TOKEN and $PORT stand for the run\'s',
      serve)
