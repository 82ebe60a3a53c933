// go_collocation.h: trapezoidal direct collocation in implicit form, assembled as a sparse NLP.
//
// A problem is N nodes over one interval [0, T]. Node k holds the node variables
//   z_k = [ x_k (nx states), xdot_k (nx state derivatives), u_k (nu controls/algebraics) ]
// so nz = 2 nx + nu. The NLP variable vector is node-major, with T last when it is free:
//   z = [ z_0, z_1, ..., z_{N-1}, T? ]                          n = N nz (+1)
// The constraint vector is
//   [ defects (N-1) nx | path constraints N n_path (node-major) | boundary n_boundary ]
// with defect (k, i) = x_{k+1,i} - x_{k,i} - h/2 (xdot_{k,i} + xdot_{k+1,i}),  h = T/(N-1),
// path constraints g(z_k) in [path_lb, path_ub] (they may read only node k), and boundary
// constraints b(z_0, z_{N-1}, T) in [boundary_lb, boundary_ub].
// The objective is J = outer(I, T) (default J = I) with the trapezoidal integral
//   I = h * sum_k w_k L(z_k),  w_0 = w_{N-1} = 1/2, else 1.
//
// Scaling is done here, not by Ipopt: the solver sees z~ = z / z_scale (T~ = T / T_scale),
// defects divided by the scale of their state, path rows by path_scale, boundary rows by
// boundary_scale and the objective by obj_scale. Callbacks always see physical values.
// Every go_nlp_eval_* function below takes and returns the scaled (solver) quantities.
//
// Threads: node work (path constraints, their finite differences, the integrand) is spread over
// the workers of a go_pool. Worker w calls the callbacks with ctx = thread_ctx[w] and nothing
// else; each node writes to its own slots and sums are reduced in node order afterwards, so
// results are bitwise identical for any number of threads.
#ifndef GAITSIM_OPTIM_GO_COLLOCATION_H_
#define GAITSIM_OPTIM_GO_COLLOCATION_H_

#define GO_INF 1e20  // bounds with |b| >= 1e19 are infinite (Ipopt's nlp_*_bound_inf)

// --- callbacks: 0 on success, non-zero on failure (the solver then shortens the step) ---------
// Every pointer argument is physical and node-local; nothing may be kept past the call.

// path constraints of node k: g (n_path) from z_k (nz)
typedef int (*go_path_fn)(void* ctx, int k, const double* z_k, double* g);

// analytic partials of the path constraints of node k, block form: write dg[r]/dz_k[j] into
// vals[p] for every pattern entry p (compressed-column order of path_col_ptr/path_row_idx) whose
// column j has path_analytic[j] != 0. Other entries are finite differences; ignore them.
typedef int (*go_path_jac_fn)(void* ctx, int k, const double* z_k, double* vals);

// integrand of node k: *L from z_k
typedef int (*go_integrand_fn)(void* ctx, int k, const double* z_k, double* L);

// analytic gradient of the integrand of node k: dL (nz, dense; entries outside integrand_vars
// must be 0)
typedef int (*go_integrand_grad_fn)(void* ctx, int k, const double* z_k, double* dL);

// diagonal of the integrand's Hessian at node k: d2L (nz, dense) with d2L[j] = d2L/dz_k[j]^2, for
// an integrand that is a sum of functions of one variable each (tracking and effort squares);
// enables the Gauss-Newton Hessian (go_nlp_eval_hess_diag)
typedef int (*go_integrand_hess_fn)(void* ctx, int k, const double* z_k, double* d2L);

// the integrand's whole Hessian at node k: H (nz x nz, dense, row-major, symmetric: both
// triangles written), every entry outside integrand_hess_mask 0. For an integrand with mixed
// curvature (e.g. the metabolic power, whose muscle terms couple a muscle's excitation,
// activation and tendon force with the coordinates and speeds it crosses); the exact
// finite-difference Hessian (go_hessian.h, go_hess_create_fd) then uses it in place of the
// diagonal
typedef int (*go_integrand_hess_block_fn)(void* ctx, int k, const double* z_k, double* H);

// boundary constraints b (n_boundary) from the first and last node variables and T
typedef int (*go_boundary_fn)(void* ctx, const double* z_first, const double* z_last, double T,
                              double* b);

// objective from the integral I and T, with its two partials (e.g. cost of transport I/(m g V T))
typedef int (*go_outer_fn)(void* ctx, double I, double T, double* J, double* dJ_dI, double* dJ_dT);

// --- description ------------------------------------------------------------------------------
typedef struct {
  int N;           // nodes (>= 2)
  int nx;          // differential states per node
  int nu;          // controls and algebraic variables per node
  int n_path;      // path constraints per node
  int n_boundary;  // boundary constraints
  int free_time;   // 1: T is the last NLP variable; 0: T = go_problem.T
} go_dims;

typedef struct {
  int node;   // node index; negative counts from the end (-1: last node)
  int var;    // node variable in [0, nz)
  double lb;  // lower bound (physical)
  double ub;  // upper bound (physical)
} go_bound_override;

typedef enum {
  GO_JAC_SPARSE = 0,  // per-node central differences over column groups + analytic columns
  GO_JAC_DENSE = 1,   // baseline (the paper): central differences of the whole constraint vector
                      // over every variable, 2 n full evaluations
  GO_JAC_SPARSE_FORWARD = 2,  // as GO_JAC_SPARSE with forward differences (step sqrt(eps)
                              // max(1, |zs|)): one evaluation per group and one at the base
                              // point instead of two per group; truncation error O(sqrt(eps))
                              // relative instead of O(eps^(2/3))
} go_jac_mode;

// Plain description; arrays are copied by go_nlp_create, callbacks and contexts are kept.
typedef struct {
  go_dims dims;

  // bounds (physical): every node, then overrides applied in order
  const double* z_lb;                    // lower bounds of node variables (nz)
  const double* z_ub;                    // upper bounds of node variables (nz)
  const go_bound_override* overrides;    // node-specific bounds (n_overrides)
  int n_overrides;
  double T;                              // final time (s) when free_time == 0
  double T_lb, T_ub;                     // bounds on T (s) when free_time == 1

  // scaling (NULL or 0: 1)
  const double* z_scale;                 // typical magnitude of each node variable (nz)
  double T_scale;                        // typical magnitude of T (s)
  const double* path_scale;              // typical magnitude of each path residual (n_path)
  const double* boundary_scale;          // (n_boundary)
  double obj_scale;                      // typical magnitude of J

  // path constraints
  go_path_fn path;                       // required when n_path > 0
  const double* path_lb;                 // (n_path), NULL: 0 (equalities)
  const double* path_ub;                 // (n_path), NULL: 0
  const int* path_col_ptr;               // pattern n_path x nz, compressed columns (nz+1)
  const int* path_row_idx;               // rows of each column (path_col_ptr[nz])
  go_path_jac_fn path_jac;               // optional analytic columns
  const unsigned char* path_analytic;    // (nz) 1: column given by path_jac (NULL: none)

  // objective
  go_integrand_fn integrand;             // NULL: I = 0
  const int* integrand_vars;             // node variables L depends on (n_integrand_vars)
  int n_integrand_vars;
  go_integrand_grad_fn integrand_grad;   // optional analytic gradient (else central differences)
  go_integrand_hess_fn integrand_hess;   // optional diagonal Hessian (Gauss-Newton Hessian)
  go_integrand_hess_block_fn integrand_hess_block;  // optional whole node Hessian (exact Hessian)
  const unsigned char* integrand_hess_mask;  // nz x nz: its possible nonzeros (required with it)
  go_outer_fn outer;                     // optional, NULL: J = I

  // boundary constraints
  go_boundary_fn boundary;               // required when n_boundary > 0
  const int* bnd_col_ptr;                // pattern n_boundary x (2 nz + 1), compressed columns:
  const int* bnd_row_idx;                //   [z_first (nz) | z_last (nz) | T (1)]
  const double* boundary_lb;             // (n_boundary), NULL: 0
  const double* boundary_ub;             // (n_boundary), NULL: 0

  // threads: worker w uses thread_ctx[w] only; the ctx of worker 0 also serves boundary/outer
  void* const* thread_ctx;               // (nthreads) per-worker scratch owned by the caller
  int nthreads;                          // workers (>= 1)
  go_jac_mode jac_mode;                  // how eval_jac computes path derivatives
} go_problem;

// evaluation counters (cumulative since create or go_nlp_reset_counts)
typedef struct {
  long path_evals;          // calls of problem.path (all uses)
  long path_jac_calls;      // calls of problem.path_jac
  long integrand_evals;     // calls of problem.integrand
  long boundary_evals;      // calls of problem.boundary
  long g_evals;             // go_nlp_eval_g calls
  long jac_evals;           // go_nlp_eval_jac calls
  long path_evals_last_jac; // path evaluations spent by the latest go_nlp_eval_jac
} go_eval_counts;

typedef struct go_nlp go_nlp;

// Check and copy the description, colour the path pattern, start the worker threads.
// Returns 0 and *out, or -1 with the reason in err. Caller frees with go_nlp_free.
int go_nlp_create(go_nlp** out, const go_problem* prob, char* err, int errsz);
void go_nlp_free(go_nlp* nlp);

// sizes: variables, constraints, Jacobian nonzeros (exact, no duplicates)
void go_nlp_sizes(const go_nlp* nlp, int* n, int* m, int* nele_jac);
int go_nlp_nz(const go_nlp* nlp);              // node variables per node
int go_nlp_var(const go_nlp* nlp, int k, int j);   // index of node k variable j in z
int go_nlp_row_defect(const go_nlp* nlp, int k, int i);  // row of defect k -> k+1, state i
int go_nlp_row_path(const go_nlp* nlp, int k, int r);    // row of path constraint r of node k
int go_nlp_row_boundary(const go_nlp* nlp, int b);       // row of boundary constraint b

// physical <-> scaled variable vectors (n); in place allowed
void go_nlp_scale_z(const go_nlp* nlp, const double* z, double* zs);
void go_nlp_unscale_z(const go_nlp* nlp, const double* zs, double* z);
// final time (s) at scaled point zs
double go_nlp_time(const go_nlp* nlp, const double* zs);

// scaled bounds: variables (n) and constraints (m)
void go_nlp_bounds(const go_nlp* nlp, double* zl, double* zu, double* gl, double* gu);

// Scaled evaluations at the scaled point zs. Return 0, or -1 when a callback failed or produced a
// non-finite value (reason: go_nlp_last_error). Derivatives: go_jacobian.h.
int go_nlp_eval_f(go_nlp* nlp, const double* zs, double* f);
int go_nlp_eval_g(go_nlp* nlp, const double* zs, double* g);          // (m)

// objective in physical units (J) from the scaled objective value
double go_nlp_objective_phys(const go_nlp* nlp, double f_scaled);
// max violation of the scaled constraint bounds by g (m): max(gl - g, g - gu, 0); inf if NaN
double go_nlp_violation(const go_nlp* nlp, const double* g);

void go_nlp_counts(const go_nlp* nlp, go_eval_counts* counts);
void go_nlp_reset_counts(go_nlp* nlp);
const char* go_nlp_last_error(const go_nlp* nlp);

// Mesh refinement that keeps every defect: node variables z0 (N0 nodes of nz = 2 nx + nu,
// physical, over [0, T], T in s) onto N nodes, N - 1 a multiple r of N0 - 1 (e.g. 20 -> 39 -> 77).
// Within each coarse interval the state derivatives and the controls are linear in time and the
// states are integrated by the trapezoid from the interval's first node; the composite trapezoid
// of a linear function is exact, so each interval ends on the coarse node again and every fine
// defect is 0 when the coarse ones are. Path constraints at the new nodes err by the
// interpolation (O(h^2)). Returns 0, or -1 when N - 1 is not a multiple of N0 - 1.
int go_refine_trapezoid(int nx, int nu, int N0, const double* z0, double T, int N, double* z);

#endif  // GAITSIM_OPTIM_GO_COLLOCATION_H_
