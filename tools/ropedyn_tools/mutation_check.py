"""Mutation check: does the test suite catch small deliberate bugs?

usage: scripts/mutation_check [--only ID,...] [--list] [--no-write] [--full] [--workdir DIR]

Each mutation of MUTATIONS replaces one snippet of one source file (a sign, a factor, a
swapped coefficient, a unit conversion, a dropped term) in a scratch copy of the working tree
(build/mutation/tree: the files git knows, copied where they differ; the working tree itself
is never changed, and the scratch file is restored after each mutation, also on Ctrl-C).
Then the copy is built incrementally (Debug, as scripts/test) and the mutation's declared
tests run first (the CTest programs and pytest files that guard its area); when they all
pass, the whole suite runs (CTest, then pytest tests/e2e tests/hard). A mutation is
"caught" when a test fails (the first failing test is reported), "survived" when the whole
suite passes. Before the first mutation the declared tests run once on the unchanged copy
(they must pass). The result table is written into docs/development/testing.md between the markers
<!-- mutation-results:begin --> and <!-- mutation-results:end --> (not with --no-write or
--only). Takes about 10 minutes on two cores when every mutation is caught by its declared
tests; each survivor costs a full suite run (~3 minutes). Run on demand, not part of CI.

A snippet is found as Fortran, not as text (`find_anchor`): blanks, comments and
continuation ampersands do not count, nor do blank lines, so the list survives reformatting
(spaces changed, a statement split over continuation lines or joined); a statement's end
(a line end without `&`) does count, and the snippet must start and end at whole names (`k`
does not match the start of `kappa`). A snippet must occur exactly once in its file
(tests/e2e/test_mutation_list.py checks that for the whole list, so the list follows the
code when it moves). The replacement takes the place of the matched text, from its first to
its last character, as it is written in the list.
"""
import argparse
import dataclasses
import filecmp
import os
import pathlib
import re
import shutil
import subprocess
import sys
import time

from ropedyn_tools.repo import ROOT
from ropedyn_tools.studies.common import run_commit, utc_stamp

DOC = ROOT / "docs" / "development" / "testing.md"
BEGIN, END = "<!-- mutation-results:begin -->", "<!-- mutation-results:end -->"


@dataclasses.dataclass(frozen=True)
class Mutation:
    id: str             #: short name
    file: str           #: path relative to the repository root
    original: str       #: snippet, occurs once in the file (as find_anchor reads it)
    replacement: str    #: what it becomes
    breaks: str         #: the physics or numerics it breaks
    ctest: tuple = ()   #: CTest programs that should catch it
    pytest: tuple = ()  #: pytest files or node ids that should catch it


#: what the check's copy runs: a change elsewhere (docs/) does not make its stamp dirty
CHECKED_PATHS = ("src", "solvers", "tests", "tools", "python", "input", "scripts",
                 "CMakeLists.txt")
RFEM = "src/models/rfem/ropedyn_rfem.f90"
RFEM_K = "src/models/rfem/ropedyn_rfem_kernels.f90"
RFEM_C = "src/models/rfem/ropedyn_rfem_create.f90"
MPP = "src/models/mpp/ropedyn_mpp.f90"
MPP_K = "src/models/mpp/ropedyn_mpp_kernels.f90"
EFFECTS = "src/models/effects/"
MOTION = "src/models/ropedyn_support_motion.f90"
SETUP = "src/models/ropedyn_rope_setup.f90"
SPEC = "src/models/ropedyn_rope_spec.f90"
SECTION = "src/models/ropedyn_rope_section.f90"
SYMP = "solvers/symplectic/ropedyn_symplectic.f90"
ORACLE = "tests/e2e/test_physics_anchors.py"
REGRESSION = "tests/e2e/test_regression.py"

MUTATIONS = [
    # --- RFEM -----------------------------------------------------------------------------
    Mutation("rfem-shear-damping-eta", SECTION,
             "s%shear_damping = r%tangential_damping*s%area",
             "s%shear_damping = r%normal_damping*s%area",
             "shear damper from the normal instead of the tangential constant",
             pytest=(ORACLE, REGRESSION)),
    Mutation("rfem-shear-factor-inverted", RFEM_C,
             "cy = sec%ga/(sec%shape_factor*dl)",
             "cy = sec%ga*sec%shape_factor/dl",
             "shear stiffness GA chi/dl instead of GA/(chi dl)",
             pytest=(ORACLE, REGRESSION)),
    Mutation("rfem-inertia-about-end", RFEM_C,
             "model%inertia = model%mass*(model%len**2/12.0_wp",
             "model%inertia = model%mass*(model%len**2/3.0_wp",
             "element inertia about its end instead of its centre (l^2/3 for l^2/12)",
             ctest=("test_mpp_anchors", "test_mpp_physics"), pytest=(ORACLE,)),
    Mutation("rfem-bending-stiffness-halved", RFEM_C,
             "cphi = sec%ei/dl",
             "cphi = sec%ei/(2.0_wp*dl)",
             "bending stiffness EI/(2 dl) instead of EI/dl",
             ctest=("test_modes",), pytest=(REGRESSION,)),
    Mutation("rfem-pin-anisotropic", RFEM_K,
             "fs = sp%ct*d\n"
             "                if (energy) e_el",
             "fs = sp%ct*[d(1), self%cy/self%cx*d(2)]\n"
             "                if (energy) e_el",
             "pinned support with the shear stiffness sideways (not isotropic)",
             pytest=(ORACLE, REGRESSION)),
    Mutation("rfem-release-ignored", RFEM,
             "self%sup(k)%active = t < self%release(k)",
             "self%sup(k)%active = .true.",
             "a released support keeps holding",
             ctest=("test_effect_anchors", "test_effects_physics")),
    Mutation("rfem-moving-support-rate-dropped", RFEM,
             "self%sup(k)%anchor_vel = ms%v",
             "self%sup(k)%anchor_vel = [0.0_wp, ms%v(2)]",
             "the supports' dampers act on the absolute, not the relative x velocity (and x "
             "work lost)",
             ctest=("test_effects_physics", "test_effects_derivatives")),
    Mutation("rfem-frame-moment-dropped", RFEM_K,
             "(fy*(s%dwx + s%ha) - fx*s%dwy + fp)",
             "(fy*(s%dwx + s%ha) + fp)",
             "tension without the moment of the turning frame (d x F)",
             ctest=("test_rfem_derivatives", "test_rfem_physics")),
    Mutation("rfem-gravity-sign", RFEM_C,
             "model%weight = merge(model%mass*model%g",
             "model%weight = merge(-model%mass*model%g",
             "gravity pointing up",
             ctest=("test_rfem_physics",)),
    # --- MPP ------------------------------------------------------------------------------
    Mutation("mpp-axial-damping-eta-bar", MPP,
             "model%ds = spec%model%mpp_axial_damping_factor*sec%axial_damping/model%l",
             "model%ds = spec%model%mpp_axial_damping_factor*sec%shear_damping/model%l",
             "member damper from the tangential instead of the normal constant",
             ctest=("test_mpp_anchors",)),
    Mutation("mpp-bending-damping-eta-bar", MPP,
             "model%db = spec%model%mpp_bending_damping_factor*sec%bending_damping/model%l",
             "model%db = spec%model%mpp_bending_damping_factor* &\n"
             "    sec%shear_damping/sec%area*sec%second_moment/model%l",
             "joint damper from the tangential instead of the normal constant",
             ctest=("test_mpp_anchors",)),
    Mutation("mpp-axial-factor-ignored", MPP,
             "model%ds = spec%model%mpp_axial_damping_factor*",
             "model%ds = 1.0_wp*",
             "mpp_axial_damping_factor ignored",
             ctest=("test_mpp_anchors",)),
    Mutation("mpp-spring-per-rope-length", MPP,
             "model%ks = sec%ea/model%l",
             "model%ks = sec%ea/spec%rope%length",
             "member spring EA/L instead of EA/l",
             ctest=("test_mpp_anchors", "test_mpp_physics")),
    Mutation("mpp-centripetal-dropped", MPP_K,
             "a2 = udd - hk*phd**2\n            self%cacc(1, k)",
             "a2 = udd\n            self%cacc(1, k)",
             "rod centre acceleration without its centripetal part",
             ctest=("test_mpp",)),
    Mutation("mpp-bottom-damper-sign", MPP_K,
             "fb = -self%k_sup*offset - self%d_sup*(pnd - bottom%v)",
             "fb = -self%k_sup*offset + self%d_sup*(pnd - bottom%v)",
             "the bottom support's damper pushes energy in",
             ctest=("test_effects_physics", "test_effects_derivatives", "test_mpp")),
    Mutation("mpp-release-ignored", MPP,
             "bottom_on = self%bottom > 0 .and. t < self%bottom_release",
             "bottom_on = self%bottom > 0",
             "the MPP's released bottom keeps holding",
             ctest=("test_effect_anchors", "test_effects_physics")),
    # --- effects --------------------------------------------------------------------------
    Mutation("drag-linear-swapped", EFFECTS + "ropedyn_effect_drag.f90",
             "eff%cn = lin_n\n        eff%ct = lin_t",
             "eff%cn = lin_t\n        eff%ct = lin_n",
             "linear normal and tangential drag swapped",
             ctest=("test_effect_anchors",)),
    Mutation("drag-tangential-area", EFFECTS + "ropedyn_effect_drag.f90",
             "eff%qt = 0.5_wp*rho*cd_t*pi*d",
             "eff%qt = 0.5_wp*rho*cd_t*d",
             "quadratic tangential drag on d l instead of the wetted area pi d l",
             pytest=(REGRESSION,)),
    Mutation("loads-frequency-without-2pi", EFFECTS + "ropedyn_effect_factory.f90",
             "loads%loads(m)%omega = 2.0_wp*pi*a%load_frequency(j)",
             "loads%loads(m)%omega = a%load_frequency(j)",
             "point-load frequency in Hz used as rad/s",
             ctest=("test_effect_anchors",)),
    Mutation("loads-phase-in-degrees", EFFECTS + "ropedyn_effect_factory.f90",
             "loads%loads(m)%phase = a%load_phase_deg(j)*pi/180.0_wp",
             "loads%loads(m)%phase = a%load_phase_deg(j)",
             "point-load phase left in degrees",
             ctest=("test_effect_anchors",)),
    Mutation("loads-moment-dropped", EFFECTS + "ropedyn_effect_loads.f90",
             "m(i) = m(i) + self%loads(k)%r*(e(1)*fl(2) - e(2)*fl(1))",
             "m(i) = m(i)",
             "a load off the element centre without its moment",
             ctest=("test_effects_derivatives", "test_effects_physics")),
    Mutation("point-mass-halved", EFFECTS + "ropedyn_effect_factory.f90",
             "mass(m) = spec%attachments%masses(k)",
             "mass(m) = 0.5_wp*spec%attachments%masses(k)",
             "point masses at half their value",
             ctest=("test_mpp_anchors", "test_effects_physics")),
    Mutation("ground-friction-halved", EFFECTS + "ropedyn_effect_ground.f90",
             "eff%mu = mu",
             "eff%mu = 0.5_wp*mu",
             "friction coefficient halved",
             ctest=("test_effects_physics",)),
    Mutation("ground-stiffness-doubled", EFFECTS + "ropedyn_effect_ground.f90",
             "eff%k = k",
             "eff%k = 2.0_wp*k",
             "contact stiffness per point k l instead of k l/2",
             ctest=("test_effect_anchors",)),
    Mutation("buoyancy-moment-dropped", EFFECTS + "ropedyn_effect_buoyancy.f90",
             "m(i) = m(i) + self%w*wt%i1*b%cs(2, i)",
             "m(i) = m(i)",
             "buoyancy of a partly wetted element without its moment (the uplift acts at "
             "the centre, not at the wetted part's)",
             ctest=("test_effects_derivatives",), pytest=("tests/e2e/test_water.py",)),
    Mutation("buoyancy-area-halved", EFFECTS + "ropedyn_effect_buoyancy.f90",
             "eff%w = rho*g*area",
             "eff%w = 0.5_wp*rho*g*area",
             "buoyancy of half the displaced water (rho_w g A / 2 per metre)",
             ctest=("test_effects_physics",), pytest=("tests/e2e/test_water.py",)),
    Mutation("added-mass-axes-swapped", EFFECTS + "ropedyn_added_mass.f90",
             "bv = l*(self%mat*ve*e + self%man*vn*nv)",
             "bv = l*(self%man*ve*e + self%mat*vn*nv)",
             "added mass: the axial coefficient across the element and the normal one "
             "along it",
             ctest=("test_effects_derivatives",), pytest=("tests/e2e/test_water.py",)),
    Mutation("section-set-ei-halved", SECTION,
             "s%ei = r%bending_stiffness",
             "s%ei = 0.5_wp*r%bending_stiffness",
             "a line given by its section: half the bending stiffness EI given",
             pytest=("tests/e2e/test_line_sections.py",)),
    Mutation("rfem-tension-sign", "src/models/rfem/ropedyn_rfem_forces.f90",
             "axial(0:n) = joint(1, :)",
             "axial(0:n) = -joint(1, :)",
             "the RFEM's tension output with the wrong sign (compression for tension)",
             ctest=("test_internal_forces",), pytest=("tests/e2e/test_internal_forces.py",)),
    Mutation("mpp-tension-sign", "src/models/mpp/ropedyn_mpp_forces.f90",
             "axial(k) = c*f(1) + s*f(2)",
             "axial(k) = -(c*f(1) + s*f(2))",
             "the MPP's tension output with the wrong sign (compression for tension)",
             ctest=("test_internal_forces",), pytest=("tests/e2e/test_internal_forces.py",)),
    Mutation("added-mass-rotary-dropped", EFFECTS + "ropedyn_added_mass.f90",
             "jb = self%man*l**3/12.0_wp",
             "jb = 0.0_wp",
             "added mass: an element's rotation about its centre without its added inertia",
             pytest=("tests/e2e/test_water.py",)),
    Mutation("mpp-water-rotary-residual", "src/models/mpp/ropedyn_mpp_water.f90",
             "self%mom(k) = self%mom(k) + (g(3) - blk(3, 3)*qacc(k))",
             "self%mom(k) = self%mom(k) + g(3)",
             "the MPP's residual in water without the rods' rotary added inertia (the "
             "Newton matrix's and the residual form's; the O(n) solve keeps it)",
             ctest=("test_mpp",)),
    Mutation("spectrum-no-balanced-pass", "solvers/ropedyn_spectrum.f90",
             "if (kr%band .and. any(real(spec%ritz, wp) > 0.0_wp",
             "if (.false. .and. any(real(spec%ritz, wp) > 0.0_wp",
             "the spectrum estimate keeps a fast Ritz value in the right half plane (a "
             "non-normal artifact) instead of estimating again on the balanced Jacobian",
             ctest=("test_spectrum_estimate",)),
    # --- supports -------------------------------------------------------------------------
    Mutation("support-phase-in-degrees", MOTION,
             "self%phase = phase_deg*pi/180.0_wp",
             "self%phase = phase_deg",
             "harmonic support phase left in degrees",
             ctest=("test_effect_anchors",)),
    Mutation("support-frequency-without-2pi", MOTION,
             "self%omega = 2.0_wp*pi*frequency",
             "self%omega = frequency",
             "harmonic support frequency in Hz used as rad/s",
             ctest=("test_effect_anchors", "test_effects_physics")),
    Mutation("table-hermite-basis", MOTION,
             "b(3) = u**2*(3.0_wp - 2.0_wp*u)",
             "b(3) = u**2*(3.0_wp - u)",
             "motion table (and coupled support) interpolation misses its rows",
             ctest=("test_effect_anchors", "test_support_motion")),
    Mutation("table-slopes-swapped", MOTION,
             "self%slope(:, k) = (h1*(rows(2:4, k) - rows(2:4, k - 1))/h0 + &\n"
             "                                h0*(rows(2:4, k + 1) - rows(2:4, k))/h1)",
             "self%slope(:, k) = (h0*(rows(2:4, k) - rows(2:4, k - 1))/h0 + &\n"
             "                                h1*(rows(2:4, k + 1) - rows(2:4, k))/h1)",
             "motion table slopes with the interval weights swapped (uneven rows)",
             ctest=("test_effect_anchors",)),
    Mutation("clamp-angle-in-degrees", SETUP,
             "angles(1) = spec%supports%top_angle_deg*pi/180.0_wp",
             "angles(1) = spec%supports%top_angle_deg",
             "top clamp angle left in degrees",
             pytest=(REGRESSION,)),
    # --- solvers --------------------------------------------------------------------------
    Mutation("mebdf-error-estimate-halved", "solvers/mebdf/ropedyn_mebdf_step.f90",
             "err1 = self%wnorm(self%d1)/self%coef(k)%tq",
             "err1 = 0.5_wp*self%wnorm(self%d1)/self%coef(k)%tq",
             "MEBDF local error estimate halved (steps too long for the tolerance)",
             ctest=("test_mebdf",)),
    Mutation("mebdf-error-constant", "solvers/mebdf/ropedyn_mebdf_coefficients.f90",
             "c%tq = real(k + 1, wp)*sum([(1.0_wp/real(j, wp), j=1, k)])",
             "c%tq = real(k + 2, wp)*sum([(1.0_wp/real(j, wp), j=1, k)])",
             "MEBDF error normalization (k+2) instead of (k+1)",
             ctest=("test_mebdf", "test_rope_solvers")),
    Mutation("cvode-rtol-loosened", "solvers/cvode/ropedyn_cvode.f90",
             "flag = FCVodeSStolerances(self%mem, real(self%options%rtol, c_double),",
             "flag = FCVodeSStolerances(self%mem, real(10*self%options%rtol, c_double),",
             "CVODE given ten times the relative tolerance asked for",
             ctest=("test_rope_solvers", "test_rfem_physics"), pytest=(REGRESSION,)),
    Mutation("cvode-quadrature-unchecked", "solvers/cvode/ropedyn_cvode.f90",
             "flag = FCVodeSetQuadErrCon(self%mem, 1_c_int)",
             "flag = FCVodeSetQuadErrCon(self%mem, 0_c_int)",
             "dissipated energy and work integrated without error control",
             ctest=("test_effects_physics",)),
    Mutation("erk-rk4-weights", "solvers/erk/ropedyn_erk_tables.f90",
             "tab%a(5, 1:4) = [0.125_wp, 0.375_wp, 0.375_wp, 0.125_wp]",
             "tab%a(5, 1:4) = [0.125_wp, 0.375_wp, 0.25_wp, 0.25_wp]",
             "erk's 3/8-rule weights changed (still consistent, no longer 4th order)",
             ctest=("test_erk_tables",)),
    Mutation("symplectic-dmap-at-start-velocity", SYMP,
             "self%vt = self%v + (0.5_wp*hh)*self%ar",
             "self%vt = self%v",
             "the D-map's dissipated energy at the velocity before the kick, not at its "
             "midpoint (the balance no longer closes exactly)",
             ctest=("test_symplectic",)),
    Mutation("chin-gradient-coefficient", "solvers/symplectic/ropedyn_split_tables.f90",
             "tab%grad = [0.0_wp, 1.0_wp/24.0_wp, 0.0_wp]",
             "tab%grad = [0.0_wp, 1.0_wp/48.0_wp, 0.0_wp]",
             "Chin's force-gradient kick with 1/48 instead of 1/24 (order 4 falls to 2)",
             ctest=("test_symplectic",)),
    # --- input handling and statics -------------------------------------------------------
    Mutation("eq13-inverted", SECTION,
             "eta_bar = rope%normal_damping*rope%shear_modulus/rope%young_modulus",
             "eta_bar = rope%normal_damping*rope%young_modulus/rope%shear_modulus",
             "default tangential damping eta E/G instead of eta G/E (paper, eq. 13)",
             ctest=("test_scene",), pytest=(ORACLE, REGRESSION)),
    Mutation("table-angle-in-degrees", "src/io/ropedyn_motion_table.f90",
             "rows(:, m) = [r(1:3), r(4)*pi/180.0_wp]",
             "rows(:, m) = [r(1:3), r(4)]",
             "motion table angles left in degrees",
             ctest=("test_effect_anchors",)),
    Mutation("shape-factor-inverted", SPEC,
             "real(wp) :: shape_factor = 10.0_wp/9.0_wp",
             "real(wp) :: shape_factor = 9.0_wp/10.0_wp",
             "default shear shape factor 9/10 instead of 10/9",
             pytest=(ORACLE, REGRESSION)),
    Mutation("statics-load-potential-sign", "src/studies/ropedyn_statics_terms.f90",
             "v = v - dot_product(force, q(1:2, body)",
             "v = v + dot_product(force, q(1:2, body)",
             "statics: the loads' potential with the wrong sign",
             ctest=("test_effect_anchors",)),
]


def normalise(text):
    """(code, where): the Fortran text without blanks, comments (outside strings) and
    continuation ampersands, statements separated by one newline; where[i] is the index in
    text of code[i]. Character strings are kept as they are."""
    code, where = [], []
    quote = None
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if quote:                           # inside a string: every character counts
            if c == "\n":                   # (an unclosed quote ends with its line)
                quote = None
            else:
                code.append(c)
                where.append(i)
                if c == quote:
                    quote = None
                i += 1
                continue
        if c == "!":                        # a comment: to the end of the line
            end = text.find("\n", i)
            i = n if end < 0 else end
            continue
        if c == "&":                        # a continuation: the statement goes on at the
            nxt = text.find("\n", i)        # next line that is not blank or a comment, at
            while 0 <= nxt < n:             # its first character or after its &
                nxt += 1
                while nxt < n and text[nxt] in " \t":
                    nxt += 1
                if nxt < n and text[nxt] in "!\n":
                    nxt = text.find("\n", nxt)
                    continue
                break
            i = n if nxt < 0 else nxt + (nxt < n and text[nxt] == "&")
            continue
        if c == "\n" or c == ";":
            if code and code[-1] != "\n":
                code.append("\n")
                where.append(i)
        elif not c.isspace():
            if c in "'\"":
                quote = c
            code.append(c)
            where.append(i)
        i += 1
    while code and code[-1] == "\n":
        code.pop()
        where.pop()
    return "".join(code), where


def _name_char(c):
    return c.isalnum() or c in "_%"


def find_anchor(text, snippet):
    """[(start, end)] of the places in text where snippet occurs as Fortran (see the module's
    docstring: blanks, comments and continuations aside, at whole names); text[start:end] is
    the matched text from its first to its last character."""
    code, where = normalise(text)
    want = normalise(snippet)[0].strip("\n")
    spans = []
    if not want:
        return spans
    k = code.find(want)
    while k >= 0:
        end = k + len(want)
        inside = (k > 0 and _name_char(want[0]) and _name_char(code[k - 1])) or \
            (end < len(code) and _name_char(want[-1]) and _name_char(code[end]))
        if not inside:
            spans.append((where[k], where[end - 1] + 1))
        k = code.find(want, k + 1)
    return spans


def check_list(root=ROOT, mutations=MUTATIONS):
    """Problems of the list: ids not unique, snippets not exactly once, no-op replacements."""
    problems = []
    ids = [m.id for m in mutations]
    problems += [f"{i}: id used twice" for i in sorted({i for i in ids if ids.count(i) > 1})]
    for m in mutations:
        path = pathlib.Path(root) / m.file
        if not path.is_file():
            problems.append(f"{m.id}: no file {m.file}")
            continue
        count = len(find_anchor(path.read_text(), m.original))
        if count != 1:
            problems.append(f"{m.id}: snippet found {count} times in {m.file}")
        if normalise(m.replacement)[0] == normalise(m.original)[0]:
            problems.append(f"{m.id}: replacement equals the snippet")
        for text in (m.original, m.replacement):
            if text != text.strip(" \t\n&"):
                problems.append(f"{m.id}: a snippet or replacement that starts or ends with a "
                                "blank, a line end or a continuation (it would be doubled)")
                break
        for test in m.pytest:
            if not (pathlib.Path(root) / test.split("::")[0]).is_file():
                problems.append(f"{m.id}: no pytest file {test}")
    return problems


def tracked_files(root):
    """Files of the working tree that git knows or would add (not ignored)."""
    out = subprocess.run(["git", "ls-files", "-z", "-co", "--exclude-standard"], cwd=root,
                         capture_output=True, check=True).stdout
    return [p for p in out.decode().split("\0") if p and (pathlib.Path(root) / p).is_file()]


def sync_tree(root, tree):
    """Make tree a copy of root's files (only changed files are copied, so that the build in
    tree stays incremental); files that root no longer has are removed. A copied file gets
    the time of the copy, not the source's: a run killed before it restored its mutation
    (SIGKILL skips the restore) leaves a mutated file newer than the source, whose objects
    a copy with the source's older time (copy2) would not rebuild, so the next run's
    baseline failed on the old mutation."""
    files = tracked_files(root)
    wanted = set(files)
    for rel in files:
        src, dst = pathlib.Path(root) / rel, tree / rel
        if not dst.exists() or not filecmp.cmp(src, dst, shallow=False):
            dst.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy(src, dst)
    for path in tree.rglob("*"):
        rel = path.relative_to(tree).as_posix()
        if rel.split("/")[0] in ("build", ".venv") or not path.is_file():
            continue
        if rel not in wanted and "__pycache__" not in rel and ".pytest_cache" not in rel:
            path.unlink()
    venv = tree / ".venv"
    if not venv.exists():
        venv.symlink_to(pathlib.Path(root) / ".venv")


class Runner:
    """Builds and tests the scratch tree."""

    def __init__(self, tree, log):
        self.tree = tree
        self.build = tree / "build" / "debug"
        self.log = log
        self.env = dict(os.environ, ROPEDYN_EXE=str(self.build / "ropedyn"),
                        PYTHONPATH=os.pathsep.join([str(tree / "python"), str(tree / "tools")]))
        self.python = str(pathlib.Path(ROOT) / ".venv" / "bin" / "python")

    def _run(self, cmd, timeout):
        with open(self.log, "a") as log:
            log.write(f"\n$ {' '.join(map(str, cmd))}\n")
            log.flush()
            try:
                proc = subprocess.run(cmd, cwd=self.tree, env=self.env, stdout=subprocess.PIPE,
                                      stderr=subprocess.STDOUT, text=True, timeout=timeout)
            except subprocess.TimeoutExpired as exc:
                out = exc.stdout.decode() if isinstance(exc.stdout, bytes) else (exc.stdout or "")
                log.write(out + f"\n(timeout after {timeout} s)\n")
                return None, out
            log.write(proc.stdout)
        return proc.returncode, proc.stdout

    def configure(self):
        code, out = self._run(["cmake", "-S", ".", "-B", str(self.build),
                               "-DCMAKE_BUILD_TYPE=Debug"], 600)
        if code != 0:
            raise RuntimeError(f"mutation_check: configure failed:\n{out[-2000:]}")

    def compile(self):
        code, _ = self._run(["cmake", "--build", str(self.build), "-j", str(os.cpu_count() or 2)],
                            1800)
        return code == 0

    def ctest(self, names=()):
        """None when every test passes, else the name of a failing one."""
        cmd = ["ctest", "--test-dir", str(self.build), "--no-tests=error", "--timeout", "900",
               "-j", str(os.cpu_count() or 2)]
        if names:
            cmd += ["-R", "^(" + "|".join(re.escape(n) for n in names) + ")$"]
        else:
            cmd += ["-LE", "long"]   # the suite scripts/test runs: not the long-horizon label
        code, out = self._run(cmd, 3600)
        if code == 0:
            return None
        if code is None:
            return "ctest (timeout)"
        failed = re.findall(r"^\s*\d+ - (\S+) \(", out, re.M)
        return failed[0] if failed else "ctest"

    def pytest(self, targets=("tests/e2e", "tests/hard")):
        """None when every test passes, else the id of the first failing one."""
        code, out = self._run([self.python, "-m", "pytest", "-x", "-q", "-rf",
                               "-p", "no:cacheprovider", *targets], 3600)
        if code == 0:
            return None
        if code is None:
            return "pytest (timeout)"
        failed = re.findall(r"^FAILED (\S+)", out, re.M) or re.findall(r"^ERROR (\S+)", out, re.M)
        return failed[0] if failed else "pytest"

    def declared(self, m):
        """First failing test among the mutation's declared tests, or None."""
        return (self.ctest(m.ctest) if m.ctest else None) or \
            (self.pytest(m.pytest) if m.pytest else None)

    def full(self):
        # the list's own check fails for every mutation (its snippet is gone): not a catch
        return self.ctest() or self.pytest(("tests/e2e", "tests/hard", "--ignore",
                                            "tests/e2e/test_mutation_list.py"))


def apply(tree, m):
    """Write the mutation into the tree's file; returns the original text."""
    path = tree / m.file
    text = path.read_text()
    spans = find_anchor(text, m.original)
    if len(spans) != 1:
        raise RuntimeError(f"{m.id}: snippet found {len(spans)} times in {m.file}")
    (start, end), = spans
    path.write_text(text[:start] + m.replacement + text[end:])
    return text


def results_table(results, commit, minutes):
    """The docs/development/testing.md section with the results; `commit`: run_commit's
    text (', commit `abc1234`')."""
    caught = sum(r["status"] == "caught" for r in results)
    lines = [BEGIN, "",
             f"Last run: {utc_stamp()}{commit}, "
             f"{len(results)} mutations, **{caught} caught**, "
             f"{len(results) - caught} not caught; {minutes:.0f} min on two cores "
             "(`scripts/mutation_check`).", "",
             "| mutation | file | what it breaks | result | first failing test |",
             "|---|---|---|---|---|"]
    for r in results:
        m = r["mutation"]
        where = "declared" if r["by"] == "declared" else "full suite"
        result = r["status"] if r["status"] != "caught" else f"caught ({where})"
        lines.append(f"| `{m.id}` | `{m.file}` | {m.breaks} | {result} | "
                     f"`{r['test'] or '-'}` |")
    lines += ["", END]
    return "\n".join(lines)


def write_doc(section):
    text = DOC.read_text()
    if BEGIN not in text or END not in text:
        raise RuntimeError(f"{DOC}: markers {BEGIN} / {END} missing")
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    DOC.write_text(head + section + tail)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="mutation_check", description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--only", help="comma-separated mutation ids")
    parser.add_argument("--list", action="store_true", help="print the mutations and exit")
    parser.add_argument("--no-write", action="store_true", help="do not update docs/development/testing.md")
    parser.add_argument("--full", action="store_true",
                        help="run the whole suite for every mutation (not the declared tests first)")
    parser.add_argument("--workdir", type=pathlib.Path, default=ROOT / "build" / "mutation",
                        help="scratch directory (default build/mutation)")
    args = parser.parse_args(argv)

    problems = check_list()
    if problems:
        print("mutation_check: the list does not match the code:\n  " + "\n  ".join(problems))
        return 2
    chosen = MUTATIONS
    if args.only:
        ids = args.only.split(",")
        unknown = set(ids) - {m.id for m in MUTATIONS}
        if unknown:
            parser.error(f"unknown mutation ids: {', '.join(sorted(unknown))}")
        chosen = [m for m in MUTATIONS if m.id in ids]
    if args.list:
        for m in chosen:
            print(f"{m.id:34s} {m.file}: {m.breaks}")
        return 0

    start = time.time()
    tree = args.workdir / "tree"
    tree.mkdir(parents=True, exist_ok=True)
    log = args.workdir / "mutation_check.log"
    log.write_text("")
    # uncommitted changes count only in what the check copies and runs, not in docs/
    commit = run_commit(ROOT, CHECKED_PATHS)
    print(f"mutation_check: {len(chosen)} mutations on a copy in {tree} (log: {log})")
    sync_tree(ROOT, tree)
    runner = Runner(tree, log)
    runner.configure()
    if not runner.compile():
        print("mutation_check: the unchanged copy does not build; see the log")
        return 2
    declared_ctest = sorted({t for m in chosen for t in m.ctest})
    declared_pytest = sorted({t for m in chosen for t in m.pytest})
    baseline = (runner.ctest(declared_ctest) if declared_ctest else None) or \
        (runner.pytest(declared_pytest) if declared_pytest else None)
    if baseline:
        print(f"mutation_check: {baseline} fails without any mutation; fix that first")
        return 2
    print(f"mutation_check: baseline ok ({time.time() - start:.0f} s)")

    results = []
    try:
        for i, m in enumerate(chosen, 1):
            t0 = time.time()
            original = apply(tree, m)
            try:
                if not runner.compile():
                    status, by, test = "build error", "-", None
                else:
                    test = None if args.full else runner.declared(m)
                    by = "declared"
                    if test is None:
                        test, by = runner.full(), "full"
                    status = "caught" if test else "SURVIVED"
            finally:
                (tree / m.file).write_text(original)
            results.append({"mutation": m, "status": status, "by": by, "test": test})
            print(f"  [{i:2d}/{len(chosen)}] {m.id:34s} {status:8s} {test or ''} "
                  f"({time.time() - t0:.0f} s)", flush=True)
    except KeyboardInterrupt:
        print("\nmutation_check: interrupted; the scratch copy is restored, the working tree "
              "was never changed")
        return 130
    finally:
        runner.compile()
    minutes = (time.time() - start) / 60
    survived = [r["mutation"].id for r in results if r["status"] != "caught"]
    print(f"mutation_check: {len(results) - len(survived)} of {len(results)} caught "
          f"in {minutes:.0f} min" + (f"; not caught: {', '.join(survived)}" if survived else ""))
    if not args.no_write and not args.only:
        write_doc(results_table(results, commit, minutes))
        print(f"mutation_check: wrote the table into {DOC.relative_to(ROOT)}")
    return 1 if survived else 0


if __name__ == "__main__":
    sys.exit(main())
