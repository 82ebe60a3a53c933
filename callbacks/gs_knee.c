// gs_knee.c: surrogate knee contact, ligaments and the reference elastic foundation (gs_knee.h).
#include "callbacks/gs_knee.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GS_KNEE_LIG_RAMP 0.05      // width of the ligament ramps in x = e/et   (-)
#define GS_KNEE_MIN_LENGTH 1e-9    // guard for divisions by a length          (m)
#define GS_KNEE_MAX_CHECK 16       // numerics whose identity a cache entry records
#define GS_KNEE_NAME_LEN 48
#define GS_KNEE_BLOCK 64           // elements per block of the surrogate's two passes

static const char* const kKneeJoints[6] = {"knee_flexion", "knee_adduction", "knee_rotation",
                                           "knee_tx", "knee_ty", "knee_tz"};

// what identifies the model a gsKneeModel was filled from (checked on every cache lookup)
typedef struct gsKneeCheck_ {
  const mjtNum* numeric_data;   // m->numeric_data
  const char* names;            // m->names
  int nnumeric, njnt, nbody;
  int nnum;                     // numerics recorded
  int num_id[GS_KNEE_MAX_CHECK];
  int num_adr[GS_KNEE_MAX_CHECK];
  int num_size[GS_KNEE_MAX_CHECK];
  char num_name[GS_KNEE_MAX_CHECK][GS_KNEE_NAME_LEN];
  // the numbers gsKneeModel holds copies of or derives from (info, layer, femur headers): their
  // addresses in the model and the values they had
  int nval;
  const mjtNum* val_ptr[4];
  int val_len[4];
  mjtNum val[4][GS_KNEE_NHEAD];
} gsKneeCheck;

// write a reason into err if there is room
static void set_err(char* err, int errlen, const char* reason) {
  if (err && errlen > 0) {
    snprintf(err, (size_t)errlen, "gs_knee: %s", reason);
  }
}

// remember numeric id (its name, address and size) in chk
static void check_add(const mjModel* m, gsKneeCheck* chk, int id) {
  if (!chk || id < 0 || chk->nnum >= GS_KNEE_MAX_CHECK) {
    return;
  }
  int k = chk->nnum++;
  chk->num_id[k] = id;
  chk->num_adr[k] = m->numeric_adr[id];
  chk->num_size[k] = m->numeric_size[id];
  snprintf(chk->num_name[k], GS_KNEE_NAME_LEN, "%s", m->names + m->name_numericadr[id]);
}

// remember n (<= GS_KNEE_NHEAD) numbers at p in chk
static void check_values(gsKneeCheck* chk, const mjtNum* p, int n) {
  if (!chk || chk->nval >= 4 || n > GS_KNEE_NHEAD) {
    return;
  }
  chk->val_ptr[chk->nval] = p;
  chk->val_len[chk->nval] = n;
  memcpy(chk->val[chk->nval], p, sizeof(mjtNum) * (size_t)n);
  chk->nval++;
}

// numeric by name: data pointer and size, NULL when absent
static const mjtNum* numeric(const mjModel* m, const char* name, int* size, gsKneeCheck* chk) {
  int id = mj_name2id(m, mjOBJ_NUMERIC, name);
  if (id < 0) {
    *size = 0;
    return NULL;
  }
  check_add(m, chk, id);
  *size = m->numeric_size[id];
  return m->numeric_data + m->numeric_adr[id];
}

// chunked numeric NAME_0, NAME_1, ... (contiguous in numeric_data): start and total size; NULL
// when NAME_0 is absent or a chunk is not contiguous with the previous one. chk records the first
// and the last chunk (together with the total size they fix the span).
static const mjtNum* numeric_chunks(const mjModel* m, const char* name, int* size,
                                    gsKneeCheck* chk) {
  char buf[64];
  int total = 0, last = -1;
  const mjtNum* start = NULL;
  for (int k = 0;; k++) {
    snprintf(buf, sizeof(buf), "%s_%d", name, k);
    int id = mj_name2id(m, mjOBJ_NUMERIC, buf);
    if (id < 0) {
      break;
    }
    const mjtNum* p = m->numeric_data + m->numeric_adr[id];
    if (k == 0) {
      start = p;
      check_add(m, chk, id);
    } else if (p != start + total) {
      *size = 0;
      return NULL;
    }
    total += m->numeric_size[id];
    last = id;
  }
  if (last >= 0 && chk && (chk->nnum == 0 || chk->num_id[chk->nnum - 1] != last)) {
    check_add(m, chk, last);
  }
  *size = total;
  return start;
}

void gs_knee_pose(const mjtNum q[6], mjtNum R[9], mjtNum t[3]) {
  mjtNum cf = cos(q[GS_KNEE_FLEX]), sf = sin(q[GS_KNEE_FLEX]);
  mjtNum ca = cos(q[GS_KNEE_ADD]), sa = sin(q[GS_KNEE_ADD]);
  mjtNum cr = cos(q[GS_KNEE_ROT]), sr = sin(q[GS_KNEE_ROT]);

  // Rx(add) * Ry(-rot), then Rz(flex) * that (OpenSim body-fixed rotation order)
  mjtNum A[9] = {cr, 0, -sr, -sa * sr, ca, -sa * cr, ca * sr, sa, ca * cr};
  for (int j = 0; j < 3; j++) {
    R[0 + j] = cf * A[0 + j] - sf * A[3 + j];
    R[3 + j] = sf * A[0 + j] + cf * A[3 + j];
    R[6 + j] = A[6 + j];
  }
  t[0] = q[GS_KNEE_TX];
  t[1] = q[GS_KNEE_TY];
  t[2] = q[GS_KNEE_TZ];
}

mjtNum gs_knee_ramp(mjtNum x, mjtNum eps) {
  return 0.5 * (x + sqrt(x * x + eps * eps));
}

// gs_knee_model_init, recording in chk (may be NULL) what identifies m
static int model_init(const mjModel* m, gsKneeModel* km, gsKneeCheck* chk, char* err,
                      int errlen) {
  int n_info, n_layer, n_femur, n_elem, n_lig;
  memset(km, 0, sizeof(*km));
  if (chk) {
    memset(chk, 0, sizeof(*chk));
    chk->numeric_data = m->numeric_data;
    chk->names = m->names;
    chk->nnumeric = m->nnumeric;
    chk->njnt = m->njnt;
    chk->nbody = m->nbody;
  }
  const mjtNum* info = numeric(m, "gs_knee_info", &n_info, chk);
  if (!info) {
    return 0;
  }

  // sizes and version
  const mjtNum* layer = numeric(m, "gs_knee_layer", &n_layer, chk);
  const mjtNum* femur = numeric_chunks(m, "gs_knee_femur", &n_femur, chk);
  const mjtNum* elem = numeric_chunks(m, "gs_knee_elements", &n_elem, chk);
  const mjtNum* lig = numeric_chunks(m, "gs_knee_ligaments", &n_lig, chk);
  if (n_info != 9 || info[0] != 2.0) {
    set_err(err, errlen, "gs_knee_info must be version 2 with 9 numbers (regenerate the model "
                         "with scripts/prepare_knee.py)");
    return -1;
  }
  for (int i = 1; i < 9; i++) {
    if (!(info[i] >= 0.0 && info[i] <= 1e6) || info[i] != floor(info[i])) {
      set_err(err, errlen, "gs_knee_info: counts must be non-negative integers");
      return -1;
    }
  }
  km->nelem[0] = (int)info[1];
  km->nelem[1] = (int)info[2];
  km->nlig = (int)info[3];
  km->ncw = (int)info[4];
  km->ncz = (int)info[5];
  km->deg = (int)info[6];
  km->ntw = (int)info[7];
  km->ntz = (int)info[8];
  km->nterm = (km->deg + 1) * (km->deg + 2) / 2;
  int ncoef = km->ncw * km->ncz * km->nterm;
  int nblock = GS_KNEE_NHEAD + 2 * ncoef + km->ntw * km->ntz;
  if (km->ncw < 1 || km->ncz < 1 || km->deg > 12 || km->ntw < 1 || km->ntz < 1 || !layer ||
      n_layer != 9 || !femur || n_femur != 2 * nblock || !elem ||
      n_elem != GS_KNEE_NELEM * (km->nelem[0] + km->nelem[1]) ||
      (km->nlig > 0 && (!lig || n_lig != GS_KNEE_NLIG * km->nlig))) {
    set_err(err, errlen, "gs_knee numerics missing or of the wrong size");
    return -1;
  }
  for (int i = 0; i < 9; i++) {
    if (!(layer[i] > 0.0)) {
      set_err(err, errlen, "gs_knee_layer: every value must be > 0");
      return -1;
    }
  }
  check_values(chk, info, 9);
  check_values(chk, layer, 9);
  km->k_over_h = layer[0];
  km->ramp_eps = layer[1];
  km->ramp_cut = layer[2];
  km->edge_width = layer[3];
  km->tau_w = layer[4];
  km->tau_z = layer[5];
  km->tau_c = layer[6];
  km->c0 = layer[7];
  km->tau_f = layer[8];
  km->itau_w = 1.0 / km->tau_w;
  km->itau_z = 1.0 / km->tau_z;
  km->itau_c = 1.0 / km->tau_c;
  km->itau_f = 1.0 / km->tau_f;
  km->iedge = 1.0 / km->edge_width;
  km->icut = 1.0 / km->ramp_cut;
  km->elem[0] = elem;
  km->elem[1] = elem + GS_KNEE_NELEM * km->nelem[0];
  for (int c = 0; c < 2; c++) {
    const mjtNum* h = femur + c * nblock;
    gsKneeFemur* fm = km->fem + c;
    check_values(chk, h, GS_KNEE_NHEAD);
    // domain and cells: W0 < W1, Z0 < Z1, positive spacing, blends within half a cell
    if (!(h[5] > h[4]) || !(h[7] > h[6]) || !(h[8] > 0.0) || !(h[9] > 0.0) ||
        !(h[10] > 0.0) || !(h[11] > 0.0) || !(2.0 * h[10] < h[8]) || !(2.0 * h[11] < h[9])) {
      set_err(err, errlen, "gs_knee_femur: bad domain, cells or blends");
      return -1;
    }
    fm->gcoef = h + GS_KNEE_NHEAD;
    fm->ecoef = fm->gcoef + ncoef;
    fm->table = fm->ecoef + ncoef;
    fm->ax = h[0];
    fm->ay = h[1];
    fm->cm = h[2];
    fm->sm = h[3];
    fm->w0 = h[4];
    fm->w1 = h[5];
    fm->z0 = h[6];
    fm->z1 = h[7];
    fm->hw = h[8];
    fm->hz = h[9];
    fm->dw = h[10];
    fm->dz = h[11];
    fm->ihw = 1.0 / h[8];
    fm->ihz = 1.0 / h[9];
    if (!(h[14] > h[13])) {
      set_err(err, errlen, "gs_knee_femur: bad cull-table range");
      return -1;
    }
    fm->s0 = h[13];
    fm->s1 = h[14];
    fm->ts = km->ntw / (h[14] - h[13]);
    fm->tz = km->ntz / (h[7] - h[6]);
    fm->scale = h[12] * km->k_over_h;
  }
  km->lig = km->nlig > 0 ? lig : NULL;

  // joints and bodies by name
  for (int i = 0; i < 6; i++) {
    km->jnt[i] = mj_name2id(m, mjOBJ_JOINT, kKneeJoints[i]);
    if (km->jnt[i] < 0) {
      set_err(err, errlen, "a knee joint (knee_flexion ... knee_tz) is missing");
      return -1;
    }
    int t = m->jnt_type[km->jnt[i]];
    if (t != mjJNT_HINGE && t != mjJNT_SLIDE) {
      set_err(err, errlen, "the six knee joints must be hinges or slides");
      return -1;
    }
    km->qadr[i] = m->jnt_qposadr[km->jnt[i]];
    km->dadr[i] = m->jnt_dofadr[km->jnt[i]];
    km->hinge[i] = t == mjJNT_HINGE;
  }
  km->body_fem = mj_name2id(m, mjOBJ_BODY, "femoral_component");
  km->body_tib = mj_name2id(m, mjOBJ_BODY, "tibial_tray");
  if (km->body_fem < 0 || km->body_tib < 0) {
    set_err(err, errlen, "bodies femoral_component and tibial_tray are required");
    return -1;
  }
  for (int i = 0; i < 6; i++) {
    if (m->jnt_bodyid[km->jnt[i]] != km->body_tib) {
      set_err(err, errlen, "the six knee joints must belong to body tibial_tray");
      return -1;
    }
  }
  return 1;
}

int gs_knee_model_init(const mjModel* m, gsKneeModel* km, char* err, int errlen) {
  return model_init(m, km, NULL, err, errlen);
}

// ---- per-model cache ----------------------------------------------------------------------
//
// Entries are immutable once published. A slot is replaced under the lock by storing a new
// entry pointer; the replaced entry stays allocated (kept on a list so it remains reachable) for
// the life of the process, because a concurrent lookup may still be reading it. Registrations
// are rare (once per prepared model), so the list stays short.
typedef struct gsKneeEntry_ {
  const mjModel* m;
  gsKneeCheck chk;
  gsKneeModel km;
  struct gsKneeEntry_* retired;  // next on the list of replaced entries
} gsKneeEntry;

static _Atomic(gsKneeEntry*) g_slots[GS_KNEE_CACHE_SLOTS];
static pthread_mutex_t g_slots_lock = PTHREAD_MUTEX_INITIALIZER;
static int g_slots_next;              // round-robin victim when all slots hold other models
static gsKneeEntry* g_retired;         // replaced entries (under the lock)

// does entry e still describe m? O(1): pointers, counts, and the recorded names/sizes
static int entry_matches(const mjModel* m, const gsKneeEntry* e) {
  const gsKneeCheck* c = &e->chk;
  const gsKneeModel* km = &e->km;
  if (e->m != m || c->numeric_data != m->numeric_data || c->names != m->names ||
      c->nnumeric != m->nnumeric || c->njnt != m->njnt || c->nbody != m->nbody) {
    return 0;
  }
  for (int k = 0; k < c->nnum; k++) {
    int id = c->num_id[k];
    if (m->numeric_adr[id] != c->num_adr[k] || m->numeric_size[id] != c->num_size[k] ||
        strcmp(m->names + m->name_numericadr[id], c->num_name[k]) != 0) {
      return 0;
    }
  }
  // same numbers where the copies came from (same addresses: numeric_data and adr checked)
  for (int k = 0; k < c->nval; k++) {
    if (memcmp(c->val_ptr[k], c->val[k], sizeof(mjtNum) * (size_t)c->val_len[k]) != 0) {
      return 0;
    }
  }
  for (int i = 0; i < 6; i++) {
    int j = km->jnt[i];
    if (m->jnt_bodyid[j] != km->body_tib || m->jnt_qposadr[j] != km->qadr[i] ||
        m->jnt_dofadr[j] != km->dadr[i] || (m->jnt_type[j] == mjJNT_HINGE) != km->hinge[i] ||
        strcmp(m->names + m->name_jntadr[j], kKneeJoints[i]) != 0) {
      return 0;
    }
  }
  return strcmp(m->names + m->name_bodyadr[km->body_fem], "femoral_component") == 0 &&
         strcmp(m->names + m->name_bodyadr[km->body_tib], "tibial_tray") == 0;
}

static int g_lazy_count;               // registrations made by gs_knee_passive (under the lock)

// register m; lazy: made by gs_knee_passive on a miss (counted, at most GS_KNEE_CACHE_LAZY_MAX,
// and skipped when another thread registered m meanwhile)
static int register_model(const mjModel* m, int lazy, char* err, int errlen) {
  if (lazy) {
    pthread_mutex_lock(&g_slots_lock);
    int full = g_lazy_count >= GS_KNEE_CACHE_LAZY_MAX;
    pthread_mutex_unlock(&g_slots_lock);
    if (full) {
      return 0;
    }
  }
  gsKneeEntry* e = calloc(1, sizeof(*e));
  if (!e) {
    set_err(err, errlen, "out of memory");
    return -1;
  }
  int rc = model_init(m, &e->km, &e->chk, err, errlen);
  if (rc != 1) {
    free(e);
    return rc;
  }
  e->m = m;
  pthread_mutex_lock(&g_slots_lock);
  int slot = -1;
  for (int i = 0; i < GS_KNEE_CACHE_SLOTS && slot < 0; i++) {
    gsKneeEntry* old = atomic_load_explicit(&g_slots[i], memory_order_acquire);
    if (old && old->m == m) {
      slot = i;  // the same address again: this model or a new one there
    }
  }
  if (lazy && (g_lazy_count >= GS_KNEE_CACHE_LAZY_MAX ||
               (slot >= 0 && entry_matches(m, atomic_load_explicit(&g_slots[slot],
                                                                     memory_order_acquire))))) {
    pthread_mutex_unlock(&g_slots_lock);
    free(e);  // full, or another thread was first
    return 1;
  }
  for (int i = 0; i < GS_KNEE_CACHE_SLOTS && slot < 0; i++) {
    if (!atomic_load_explicit(&g_slots[i], memory_order_acquire)) {
      slot = i;
    }
  }
  if (slot < 0) {
    slot = g_slots_next;
    g_slots_next = (g_slots_next + 1) % GS_KNEE_CACHE_SLOTS;
  }
  gsKneeEntry* old = atomic_exchange_explicit(&g_slots[slot], e, memory_order_acq_rel);
  if (old) {
    old->retired = g_retired;
    g_retired = old;
  }
  g_lazy_count += lazy;
  pthread_mutex_unlock(&g_slots_lock);
  return 1;
}

int gs_knee_register(const mjModel* m, char* err, int errlen) {
  return register_model(m, 0, err, errlen);
}

const gsKneeModel* gs_knee_lookup(const mjModel* m) {
  for (int i = 0; i < GS_KNEE_CACHE_SLOTS; i++) {
    const gsKneeEntry* e = atomic_load_explicit(&g_slots[i], memory_order_acquire);
    if (e && e->m == m) {
      return entry_matches(m, e) ? &e->km : NULL;
    }
  }
  return NULL;
}

// C-infinity step: 0 for t <= 0, 1 for t >= 1, 1 / (1 + exp((1 - 2t) / (t (1 - t)))) between
// (exp overflows to +inf near t = 0, which gives exactly 0)
static mjtNum smooth_step(mjtNum t) {
  if (t <= 0.0) {
    return 0.0;
  }
  if (t >= 1.0) {
    return 1.0;
  }
  return 1.0 / (1.0 + exp((1.0 - 2.0 * t) / (t * (1.0 - t))));
}

// partition of unity along one axis, for x inside [x0, x0 + nc h]: the one or two cells of x
// and their weights
static int pu_axis(mjtNum x, mjtNum x0, mjtNum h, mjtNum ih, mjtNum d, int nc, int idx[2],
                   mjtNum wt[2]) {
  int i = (int)((x - x0) * ih);
  i = i < 0 ? 0 : (i > nc - 1 ? nc - 1 : i);
  mjtNum s = x - (x0 + i * h);
  if (i > 0 && s < d) {
    mjtNum up = smooth_step((s + d) / (2.0 * d));
    idx[0] = i - 1;
    idx[1] = i;
    wt[0] = 1.0 - up;
    wt[1] = up;
    return 2;
  }
  if (i < nc - 1 && s > h - d) {
    mjtNum up = smooth_step((s - h + d) / (2.0 * d));
    idx[0] = i;
    idx[1] = i + 1;
    wt[0] = 1.0 - up;
    wt[1] = up;
    return 2;
  }
  idx[0] = i;
  wt[0] = 1.0;
  return 1;
}

// sum over a = 0..deg, b = 0..deg-a of c_ab u^a v^b (a outer), by Horner in v then u
static mjtNum poly2(const mjtNum* c, int deg, mjtNum u, mjtNum v) {
  if (deg == 4) {
    mjtNum r0 = c[0] + v * (c[1] + v * (c[2] + v * (c[3] + v * c[4])));
    mjtNum r1 = c[5] + v * (c[6] + v * (c[7] + v * c[8]));
    mjtNum r2 = c[9] + v * (c[10] + v * c[11]);
    mjtNum r3 = c[12] + v * c[13];
    return r0 + u * (r1 + u * (r2 + u * (r3 + u * c[14])));
  }
  int off = (deg + 1) * (deg + 2) / 2;
  mjtNum res = 0.0;
  for (int a = deg; a >= 0; a--) {
    int n = deg + 1 - a;
    off -= n;
    mjtNum inner = 0.0;
    for (int b = n - 1; b >= 0; b--) {
      inner = inner * v + c[off + b];
    }
    res = res * u + inner;
  }
  return res;
}

// a partition-of-unity field (coefficients coef) of condyle fm at (w, z) inside the domain
static mjtNum pu_field(const gsKneeModel* km, const gsKneeFemur* fm, const mjtNum* coef,
                       mjtNum w, mjtNum z) {
  int iw[2], iz[2];
  mjtNum aw[2], az[2];
  int nw = pu_axis(w, fm->w0, fm->hw, fm->ihw, fm->dw, km->ncw, iw, aw);
  int nz = pu_axis(z, fm->z0, fm->hz, fm->ihz, fm->dz, km->ncz, iz, az);
  if (nw == 1 && nz == 1) {
    // inside one cell (most points): its polynomial alone
    mjtNum u = (w - (fm->w0 + (iw[0] + 0.5) * fm->hw)) * (2.0 * fm->ihw);
    mjtNum v = (z - (fm->z0 + (iz[0] + 0.5) * fm->hz)) * (2.0 * fm->ihz);
    return poly2(coef + (iw[0] * km->ncz + iz[0]) * km->nterm, km->deg, u, v);
  }
  mjtNum res = 0.0;
  for (int a = 0; a < nw; a++) {
    mjtNum u = (w - (fm->w0 + (iw[a] + 0.5) * fm->hw)) * (2.0 * fm->ihw);
    for (int b = 0; b < nz; b++) {
      mjtNum v = (z - (fm->z0 + (iz[b] + 0.5) * fm->hz)) * (2.0 * fm->ihz);
      const mjtNum* c = coef + (iw[a] * km->ncz + iz[b]) * km->nterm;
      res += aw[a] * az[b] * poly2(c, km->deg, u, v);
    }
  }
  return res;
}

void gs_knee_surrogate(const gsKneeModel* km, const mjtNum q[6], gsKneeContact* out) {
  mjtNum R[9], t[3];
  mjtNum eps2 = km->ramp_eps * km->ramp_eps, cut = km->ramp_cut;
  gs_knee_pose(q, R, t);
  memset(out, 0, sizeof(*out));

  // element centre c in the femoral frame: R^T (c - t) = R^T c - R^T t
  mjtNum rt[3] = {R[0] * t[0] + R[3] * t[1] + R[6] * t[2], R[1] * t[0] + R[4] * t[1] + R[7] * t[2],
                  R[2] * t[0] + R[5] * t[1] + R[8] * t[2]};

  for (int c = 0; c < 2; c++) {
    const gsKneeFemur* fm = km->fem + c;
    mjtNum f[3] = {0, 0, 0}, mo[3] = {0, 0, 0};
    // A = rho sin(phi - phi_mid) = vx cm + vy sm, C = rho cos(phi - phi_mid) = vx sm - vy cm with
    // (vx, vy) = (R^T c)_xy - R^T t - (ax, ay): A = a . c - a0, C = b . c - b0 (rows of R^T
    // combined), z = (R^T c)_z - (R^T t)_z; rho^2 = A^2 + C^2
    mjtNum av[3], bv[3];
    for (int i = 0; i < 3; i++) {
      av[i] = R[3 * i] * fm->cm + R[3 * i + 1] * fm->sm;
      bv[i] = R[3 * i] * fm->sm - R[3 * i + 1] * fm->cm;
    }
    mjtNum ox = rt[0] + fm->ax, oy = rt[1] + fm->ay, oz = rt[2];
    mjtNum a0 = ox * fm->cm + oy * fm->sm, b0 = ox * fm->sm - oy * fm->cm;
    int n = km->nelem[c];
    const mjtNum* ex = km->elem[c];
    const mjtNum *ey = ex + n, *ez = ex + 2 * n, *enx = ex + 3 * n, *eny = ex + 4 * n;
    const mjtNum *enz = ex + 5 * n, *ea = ex + 6 * n;
    mjtNum a_0 = av[0], a_1 = av[1], a_2 = av[2], b_0 = bv[0], b_1 = bv[1], b_2 = bv[2];
    mjtNum r_2 = R[2], r_5 = R[5], r_8 = R[8];
    mjtNum z0 = fm->z0, z1 = fm->z1, s0 = fm->s0, s1 = fm->s1;

    for (int j0 = 0; j0 < n; j0 += GS_KNEE_BLOCK) {
      int nb = n - j0 < GS_KNEE_BLOCK ? n - j0 : GS_KNEE_BLOCK;
      mjtNum bA[GS_KNEE_BLOCK], bC[GS_KNEE_BLOCK], bz[GS_KNEE_BLOCK], bs[GS_KNEE_BLOCK];
      mjtNum bok[GS_KNEE_BLOCK];

      // pass 1, branch-free (the compiler vectorizes it): position about the condyle's axis,
      // s = A / C, and whether the element lies in the domain
      for (int k = 0; k < nb; k++) {
        int j = j0 + k;
        mjtNum z = r_2 * ex[j] + r_5 * ey[j] + r_8 * ez[j] - oz;
        mjtNum C = b_0 * ex[j] + b_1 * ey[j] + b_2 * ez[j] - b0;
        mjtNum A = a_0 * ex[j] + a_1 * ey[j] + a_2 * ez[j] - a0;
        mjtNum sv = A / C;
        bA[k] = A;
        bC[k] = C;
        bz[k] = z;
        bs[k] = sv;
        bok[k] = (z > z0 && z < z1 && C > 0.0 && sv > s0 && sv < s1) ? 1.0 : 0.0;
      }

      // pass 2: the elements in the domain
      for (int k = 0; k < nb; k++) {
        if (bok[k] == 0.0) {
          continue;
        }
        int j = j0 + k;
        mjtNum A = bA[k], C = bC[k], z = bz[k], sv = bs[k];

        // cull table: rho^2 beyond (bound of G over this bin + 2 b)^2 means no load (exact);
        // a negative entry: the masks are exactly 1 throughout the bin
        mjtNum r2 = A * A + C * C;
        int ti = (int)((sv - fm->s0) * fm->ts), tj = (int)((z - fm->z0) * fm->tz);
        ti = ti > km->ntw - 1 ? km->ntw - 1 : ti;
        tj = tj > km->ntz - 1 ? km->ntz - 1 : tj;
        mjtNum bin = fm->table[ti * km->ntz + tj];
        if (r2 > fabs(bin)) {
          continue;
        }
        mjtNum rho = sqrt(r2);
        mjtNum inv = 1.0 / rho;
        mjtNum w = A * inv, cc = C * inv;
        if (!(w > fm->w0 && w < fm->w1 && cc > km->c0)) {
          continue;  // domain mask exactly 0
        }

        // radial overlap; nothing below -2 b
        mjtNum g = pu_field(km, fm, fm->gcoef, w, z) - rho;
        if (g <= -2.0 * cut) {
          continue;
        }
        mjtNum mask = 1.0;
        if (!(bin < 0.0)) {
          mask = smooth_step((w - fm->w0) * km->itau_w) * smooth_step((fm->w1 - w) * km->itau_w) *
                 smooth_step((cc - km->c0) * km->itau_c) * smooth_step((z - fm->z0) * km->itau_z) *
                 smooth_step((fm->z1 - z) * km->itau_z);
          mask *= smooth_step(pu_field(km, fm, fm->ecoef, w, z) * km->iedge + 0.5);
          if (mask == 0.0) {
            continue;
          }
        }

        // pressure x area along the element normal
        mjtNum r = 0.5 * (g + sqrt(g * g + eps2)) * smooth_step((g + 2.0 * cut) * km->icut);
        // cosine of the element normal to the radial direction: -(v . n')_xy / rho, in the rotated
        // basis -(A n_a + C n_b) / rho
        mjtNum n0 = enx[j], n1 = eny[j], n2 = enz[j];
        mjtNum na = a_0 * n0 + a_1 * n1 + a_2 * n2;
        mjtNum nbv = b_0 * n0 + b_1 * n1 + b_2 * n2;
        mjtNum cosn = -(A * na + C * nbv) * inv;
        cosn *= smooth_step(cosn * km->itau_f);
        mjtNum wgt = fm->scale * r * cosn * mask * ea[j];
        f[0] -= wgt * n0;
        f[1] -= wgt * n1;
        f[2] -= wgt * n2;
        mo[0] -= wgt * (ey[j] * n2 - ez[j] * n1);
        mo[1] -= wgt * (ez[j] * n0 - ex[j] * n2);
        mo[2] -= wgt * (ex[j] * n1 - ey[j] * n0);
      }
    }
    for (int i = 0; i < 3; i++) {
      out->force[c][i] = f[i];
      out->moment[c][i] = mo[i];
    }
    out->magnitude[c] = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  }

  // total
  mjtNum s[3];
  for (int i = 0; i < 3; i++) {
    s[i] = out->force[0][i] + out->force[1][i];
  }
  out->total = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
}

mjtNum gs_knee_ligament_force(const mjtNum row[GS_KNEE_NLIG], mjtNum length, mjtNum speed) {
  mjtNum k = row[6], l0 = row[7], et = row[8], c = row[9];
  if (l0 < GS_KNEE_MIN_LENGTH) {
    l0 = GS_KNEE_MIN_LENGTH;
  }
  if (et < 1e-6) {
    et = 1e-6;
  }

  // smooth toe + linear spring: k et [r(x)^2 - r(x-1)^2] / 2
  mjtNum e = length / l0 - 1.0;
  mjtNum x = e / et;
  mjtNum r0 = gs_knee_ramp(x, GS_KNEE_LIG_RAMP);
  mjtNum r1 = gs_knee_ramp(x - 1.0, GS_KNEE_LIG_RAMP);
  mjtNum spring = 0.5 * k * et * (r0 * r0 - r1 * r1);

  // damping while taut: c de/dt s(e)
  mjtNum w = GS_KNEE_LIG_RAMP * et;
  mjtNum step = 0.5 * (1.0 + e / sqrt(e * e + w * w));
  return spring + c * (speed / l0) * step;
}

// velocity (world) of body b's motion: angular w and linear v0 of the point at the origin of the
// world frame moving with b, from MuJoCo's com-based cvel (rotation; translation of the point at
// the subtree centre of mass of b's root), so v(p) = v0 + w x p
static void body_twist(const mjModel* m, const mjData* d, int b, mjtNum w[3], mjtNum v0[3]) {
  const mjtNum* cv = d->cvel + 6 * b;
  const mjtNum* c = d->subtree_com + 3 * m->body_rootid[b];
  w[0] = cv[0];
  w[1] = cv[1];
  w[2] = cv[2];
  // v0 = v_c + w x (0 - c)
  v0[0] = cv[3] - (w[1] * c[2] - w[2] * c[1]);
  v0[1] = cv[4] - (w[2] * c[0] - w[0] * c[2]);
  v0[2] = cv[5] - (w[0] * c[1] - w[1] * c[0]);
}

void gs_knee_passive_model(const gsKneeModel* km, const mjModel* m, mjData* d, gsKneeLoads* out) {
  mjtNum q[6];
  gsKneeLoads loads;
  const mjtNum* xt = d->xpos + 3 * km->body_tib;
  const mjtNum* Rt = d->xmat + 9 * km->body_tib;
  const mjtNum* xf = d->xpos + 3 * km->body_fem;
  const mjtNum* Rf = d->xmat + 9 * km->body_fem;
  memset(&loads, 0, sizeof(loads));

  // coordinates (addresses cached in km)
  for (int i = 0; i < 6; i++) {
    q[i] = d->qpos[km->qadr[i]];
  }

  // everything acting on the tibia is summed into a force F and a moment M about the tibial
  // origin xt (world frame), projected on the six joints once at the end
  mjtNum F[3] = {0, 0, 0}, M[3] = {0, 0, 0};

  // contact: per compartment a force at the tibial_tray origin plus its moment (tibial frame)
  gs_knee_surrogate(km, q, &loads.contact);
  {
    mjtNum fl[3], ml[3];
    for (int i = 0; i < 3; i++) {
      fl[i] = loads.contact.force[0][i] + loads.contact.force[1][i];
      ml[i] = loads.contact.moment[0][i] + loads.contact.moment[1][i];
    }
    mjtNum fw[3], mw[3];
    mju_mulMatVec(fw, Rt, fl, 3, 3);
    mju_mulMatVec(mw, Rt, ml, 3, 3);
    mju_addTo3(F, fw);
    mju_addTo3(M, mw);
  }

  // ligaments: tension along the line tibial point -> femoral point, on the tibia; lengthening
  // speed from the two bodies' twists (one look-up each, not one per bundle)
  mjtNum wf[3], vf0[3], wt[3], vt0[3];
  body_twist(m, d, km->body_fem, wf, vf0);
  body_twist(m, d, km->body_tib, wt, vt0);
  for (int b = 0; b < km->nlig; b++) {
    const mjtNum* row = km->lig + GS_KNEE_NLIG * b;
    mjtNum pf[3], pt[3], u[3];
    mju_mulMatVec(pf, Rf, row, 3, 3);
    mju_mulMatVec(pt, Rt, row + 3, 3, 3);
    for (int i = 0; i < 3; i++) {
      pf[i] += xf[i];
      pt[i] += xt[i];
      u[i] = pf[i] - pt[i];
    }
    mjtNum len = mju_norm3(u);
    if (len < GS_KNEE_MIN_LENGTH) {
      continue;
    }
    mju_scl3(u, u, 1.0 / len);
    // relative velocity of the femoral point against the tibial point
    mjtNum dv[3];
    for (int i = 0; i < 3; i++) {
      int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
      dv[i] = vf0[i] - vt0[i] + (wf[i1] * pf[i2] - wf[i2] * pf[i1]) -
              (wt[i1] * pt[i2] - wt[i2] * pt[i1]);
    }
    mjtNum speed = u[0] * dv[0] + u[1] * dv[1] + u[2] * dv[2];
    mjtNum ten = gs_knee_ligament_force(row, len, speed);
    mjtNum f[3] = {ten * u[0], ten * u[1], ten * u[2]};
    mjtNum r[3] = {pt[0] - xt[0], pt[1] - xt[1], pt[2] - xt[2]};
    F[0] += f[0];
    F[1] += f[1];
    F[2] += f[2];
    M[0] += r[1] * f[2] - r[2] * f[1];
    M[1] += r[2] * f[0] - r[0] * f[2];
    M[2] += r[0] * f[1] - r[1] * f[0];
    loads.ligament_force += ten;
  }

  // generalized forces: hinge a.(M + (xt - anchor) x F), slide a.F (joints of the tibia body)
  for (int i = 0; i < 6; i++) {
    int j = km->jnt[i];
    const mjtNum* a = d->xaxis + 3 * j;
    mjtNum Qi;
    if (km->hinge[i]) {
      const mjtNum* o = d->xanchor + 3 * j;
      mjtNum r[3] = {xt[0] - o[0], xt[1] - o[1], xt[2] - o[2]};
      mjtNum mx = M[0] + r[1] * F[2] - r[2] * F[1];
      mjtNum my = M[1] + r[2] * F[0] - r[0] * F[2];
      mjtNum mz = M[2] + r[0] * F[1] - r[1] * F[0];
      Qi = a[0] * mx + a[1] * my + a[2] * mz;
    } else {
      Qi = a[0] * F[0] + a[1] * F[1] + a[2] * F[2];
    }
    d->qfrc_passive[km->dadr[i]] += Qi;
    loads.qfrc[i] = Qi;
  }
  if (out) {
    *out = loads;
  }
}

int gs_knee_passive(const mjModel* m, mjData* d, gsKneeLoads* out) {
  const gsKneeModel* cached = gs_knee_lookup(m);
  if (!cached && register_model(m, 1, NULL, 0) == 1) {
    cached = gs_knee_lookup(m);  // registered now (by this thread or another one)
  }
  if (cached) {
    gs_knee_passive_model(cached, m, d, out);
    return 1;
  }
  gsKneeModel km;
  int rc = gs_knee_model_init(m, &km, NULL, 0);
  if (rc != 1) {
    return rc;
  }
  gs_knee_passive_model(&km, m, d, out);
  return 1;
}

// ---- reference elastic foundation ---------------------------------------------------------

double gs_knee_ef_layer_modulus(double young, double poisson) {
  return (1.0 - poisson) * young / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
}

void gs_knee_ef_free(gsKneeEf* ef) {
  free(ef->cell_start);
  free(ef->cell_elem);
  free(ef->vt);
  free(ef->depth);
  ef->cell_start = ef->cell_elem = NULL;
  ef->vt = ef->depth = NULL;
}

int gs_knee_ef_build(gsKneeEf* ef, char* err, int errlen) {
  double xmin = 1e30, xmax = -1e30, zmin = 1e30, zmax = -1e30;
  ef->cell_start = ef->cell_elem = NULL;
  ef->vt = ef->depth = NULL;
  if (ef->nv <= 0 || ef->nf <= 0 || ef->ne <= 0 || !ef->v || !ef->f || !ef->ec || !ef->en ||
      !ef->ea || !ef->ecomp || !(ef->k_over_h > 0.0) || !(ef->reach > 0.0)) {
    set_err(err, errlen, "elastic foundation: empty surface or bad parameters");
    return -1;
  }
  for (int i = 0; i < 3 * ef->nf; i++) {
    if (ef->f[i] < 0 || ef->f[i] >= ef->nv) {
      set_err(err, errlen, "elastic foundation: face index out of range");
      return -1;
    }
  }

  // grid over the elements' x-z extent, cells about 2 mm
  for (int j = 0; j < ef->ne; j++) {
    double x = ef->ec[3 * j], z = ef->ec[3 * j + 2];
    xmin = x < xmin ? x : xmin;
    xmax = x > xmax ? x : xmax;
    zmin = z < zmin ? z : zmin;
    zmax = z > zmax ? z : zmax;
  }
  ef->cell = 0.002;
  ef->x0 = xmin - 1e-6;
  ef->z0 = zmin - 1e-6;
  ef->gx = (int)((xmax - ef->x0) / ef->cell) + 1;
  ef->gz = (int)((zmax - ef->z0) / ef->cell) + 1;
  int ncell = ef->gx * ef->gz;
  ef->cell_start = calloc((size_t)ncell + 1, sizeof(int));
  ef->cell_elem = malloc(sizeof(int) * (size_t)ef->ne);
  ef->vt = malloc(sizeof(double) * 3 * (size_t)ef->nv);
  ef->depth = malloc(sizeof(double) * (size_t)ef->ne);
  if (!ef->cell_start || !ef->cell_elem || !ef->vt || !ef->depth) {
    gs_knee_ef_free(ef);
    set_err(err, errlen, "elastic foundation: out of memory");
    return -1;
  }

  // counting sort of the elements into cells (CSR)
  for (int j = 0; j < ef->ne; j++) {
    int cx = (int)((ef->ec[3 * j] - ef->x0) / ef->cell);
    int cz = (int)((ef->ec[3 * j + 2] - ef->z0) / ef->cell);
    ef->cell_start[cx * ef->gz + cz + 1]++;
  }
  for (int c = 0; c < ncell; c++) {
    ef->cell_start[c + 1] += ef->cell_start[c];
  }
  int* fill = calloc((size_t)ncell, sizeof(int));
  if (!fill) {
    gs_knee_ef_free(ef);
    set_err(err, errlen, "elastic foundation: out of memory");
    return -1;
  }
  for (int j = 0; j < ef->ne; j++) {
    int cx = (int)((ef->ec[3 * j] - ef->x0) / ef->cell);
    int cz = (int)((ef->ec[3 * j + 2] - ef->z0) / ef->cell);
    int c = cx * ef->gz + cz;
    ef->cell_elem[ef->cell_start[c] + fill[c]++] = j;
  }
  free(fill);
  return 0;
}

int gs_knee_ef_eval(gsKneeEf* ef, const double R[9], const double t[3], gsKneeContact* out) {
  double ymax = -1e30;
  int ncontact = 0;
  memset(out, 0, sizeof(*out));

  // femoral vertices into the tibial frame
  for (int i = 0; i < ef->nv; i++) {
    const double* p = ef->v + 3 * i;
    double* q = ef->vt + 3 * i;
    for (int r = 0; r < 3; r++) {
      q[r] = t[r] + R[3 * r] * p[0] + R[3 * r + 1] * p[1] + R[3 * r + 2] * p[2];
    }
  }
  for (int j = 0; j < ef->ne; j++) {
    ef->depth[j] = -1.0;
    ymax = ef->ec[3 * j + 1] > ymax ? ef->ec[3 * j + 1] : ymax;
  }

  // every femoral face that faces the tibia and reaches down to the insert
  for (int fi = 0; fi < ef->nf; fi++) {
    const double* a = ef->vt + 3 * ef->f[3 * fi];
    const double* b = ef->vt + 3 * ef->f[3 * fi + 1];
    const double* c = ef->vt + 3 * ef->f[3 * fi + 2];
    double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double ny = e1[2] * e2[0] - e1[0] * e2[2];
    double ylo = fmin(a[1], fmin(b[1], c[1]));
    if (ny >= 0.0 || ylo > ymax + ef->reach) {
      continue;
    }

    // grid cells under the face's x-z box, widened by the reach (tilted normals)
    double m = ef->reach;
    int cx0 = (int)floor((fmin(a[0], fmin(b[0], c[0])) - m - ef->x0) / ef->cell);
    int cx1 = (int)floor((fmax(a[0], fmax(b[0], c[0])) + m - ef->x0) / ef->cell);
    int cz0 = (int)floor((fmin(a[2], fmin(b[2], c[2])) - m - ef->z0) / ef->cell);
    int cz1 = (int)floor((fmax(a[2], fmax(b[2], c[2])) + m - ef->z0) / ef->cell);
    cx0 = cx0 < 0 ? 0 : cx0;
    cz0 = cz0 < 0 ? 0 : cz0;
    cx1 = cx1 >= ef->gx ? ef->gx - 1 : cx1;
    cz1 = cz1 >= ef->gz ? ef->gz - 1 : cz1;
    for (int gx = cx0; gx <= cx1; gx++) {
      for (int gz = cz0; gz <= cz1; gz++) {
        int cell = gx * ef->gz + gz;
        for (int k = ef->cell_start[cell]; k < ef->cell_start[cell + 1]; k++) {
          // Moller-Trumbore: element centre o + s n meets the face
          int j = ef->cell_elem[k];
          const double* o = ef->ec + 3 * j;
          const double* n = ef->en + 3 * j;
          double h[3] = {n[1] * e2[2] - n[2] * e2[1], n[2] * e2[0] - n[0] * e2[2],
                         n[0] * e2[1] - n[1] * e2[0]};
          double det = e1[0] * h[0] + e1[1] * h[1] + e1[2] * h[2];
          if (fabs(det) < 1e-14) {
            continue;
          }
          double inv = 1.0 / det;
          double s[3] = {o[0] - a[0], o[1] - a[1], o[2] - a[2]};
          double u = (s[0] * h[0] + s[1] * h[1] + s[2] * h[2]) * inv;
          if (u < 0.0 || u > 1.0) {
            continue;
          }
          double qv[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2],
                          s[0] * e1[1] - s[1] * e1[0]};
          double v = (n[0] * qv[0] + n[1] * qv[1] + n[2] * qv[2]) * inv;
          if (v < 0.0 || u + v > 1.0) {
            continue;
          }
          double dist = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) * inv;
          if (fabs(dist) < ef->reach && -dist > ef->depth[j]) {
            ef->depth[j] = -dist;
          }
        }
      }
    }
  }

  // pressure p = K/h max(d, 0) on every element, summed per compartment
  for (int j = 0; j < ef->ne; j++) {
    double dpen = ef->depth[j];
    if (dpen <= 0.0) {
      continue;
    }
    ncontact++;
    int c = ef->ecomp[j] ? 1 : 0;
    double w = ef->k_over_h * dpen * ef->ea[j];
    const double* p = ef->ec + 3 * j;
    const double* n = ef->en + 3 * j;
    double f[3] = {-w * n[0], -w * n[1], -w * n[2]};
    for (int i = 0; i < 3; i++) {
      out->force[c][i] += f[i];
    }
    out->moment[c][0] += p[1] * f[2] - p[2] * f[1];
    out->moment[c][1] += p[2] * f[0] - p[0] * f[2];
    out->moment[c][2] += p[0] * f[1] - p[1] * f[0];
  }
  double s[3];
  for (int c = 0; c < 2; c++) {
    const double* f = out->force[c];
    out->magnitude[c] = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  }
  for (int i = 0; i < 3; i++) {
    s[i] = out->force[0][i] + out->force[1][i];
  }
  out->total = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
  return ncontact;
}
