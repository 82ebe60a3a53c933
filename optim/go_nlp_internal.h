// go_nlp_internal.h: the collocation NLP object shared by go_collocation.c and go_jacobian.c.
// Not part of the public interface.
#ifndef GAITSIM_OPTIM_GO_NLP_INTERNAL_H_
#define GAITSIM_OPTIM_GO_NLP_INTERNAL_H_

#include "optim/go_collocation.h"
#include "optim/go_threads.h"

// per-worker scratch, physical units; never touched by another worker
typedef struct {
  double* z;        // node variables at the base point (nz)
  double* zp;       // node variables, + perturbation (nz)
  double* zm;       // node variables, - perturbation (nz)
  double* gp;       // path values at zp (n_path)
  double* gm;       // path values at zm (n_path)
  double* jv;       // analytic path partials from path_jac (nnz_p)
  double* fz;       // dense baseline: whole scaled variable vector (n)
  double* fgp;      // dense baseline: whole scaled constraint vector at + (m)
  double* fgm;      // dense baseline: whole scaled constraint vector at - (m)
  double* bz;       // boundary arguments [z_first | z_last | T] (2 nz + 1)
  long path_evals;      // counters of this worker
  long path_jac_calls;
  long integrand_evals;
  long boundary_evals;
  char pad[64];     // keep counters of neighbouring workers off one cache line
} go_worker;

// what the parallel node loop computes
typedef enum {
  GO_TASK_G = 0,      // path values of node k
  GO_TASK_JAC,        // path Jacobian block of node k
  GO_TASK_L,          // integrand of node k
  GO_TASK_DL,         // integrand and its gradient at node k
  GO_TASK_DENSE_JAC,  // dense baseline: Jacobian column v
  GO_TASK_DENSE_GRAD, // dense baseline: gradient entry v
} go_task_kind;

struct go_nlp {
  go_problem prob;        // callbacks, contexts, dims (array pointers are not used after create)
  int N, nx, nu, nz;      // nodes, states, controls, node variables (2 nx + nu)
  int np, nb, free_time;  // path rows per node, boundary rows, T free
  int n, m, nele;         // variables, constraints, Jacobian nonzeros
  int nnz_p;              // path pattern entries per node
  int off_path, off_bnd;  // first Jacobian entry of the path blocks / boundary
  int row_path, row_bnd;  // first row of the path constraints / boundary constraints
  double T_fixed;         // T when not free (s)
  double T_scale;         // scale of T (s)
  double obj_scale;       // scale of the objective

  double* zl;             // physical variable bounds (n)
  double* zu;
  double* zscale;         // node variable scales (nz)
  double* pscale;         // path row scales (n_path)
  double* plb;            // path bounds, physical (n_path)
  double* pub;
  double* bscale;         // boundary row scales (n_boundary)
  double* blb;            // boundary bounds, physical (n_boundary)
  double* bub;
  int* p_colptr;          // path pattern (nz+1)
  int* p_row;             // (nnz_p)
  unsigned char* analytic;// analytic path columns (nz)
  int ngroup;             // finite-difference colour groups of the path pattern
  int* grp_ptr;           // group g holds columns grp_col[grp_ptr[g] .. grp_ptr[g+1]) (ngroup+1)
  int* grp_col;           // (nz)
  int* ivars;             // integrand variables (n_ivars)
  int n_ivars;
  int* b_colptr;          // boundary pattern (2 nz + 2)
  int* b_row;             // (b_colptr[2 nz + 1])
  double* bp;             // boundary scratch + (n_boundary), serial parts only
  double* bm;             // boundary scratch - (n_boundary)
  int* irow;              // Jacobian pattern (nele)
  int* jcol;
  int* jc_ptr;            // Jacobian entries by column, for the dense baseline (n+1)
  int* jc_ent;            // (nele)
  double* Lk;             // integrand per node (N)
  double* dLk;            // physical integrand gradient per node (N x nz)
  int* status;            // per item status of the last parallel loop (max(N, n))
  go_worker* workers;     // (nthreads)
  int nthreads;
  go_pool* pool;

  go_jac_mode mode;       // sparse or dense finite differences
  long g_evals, jac_evals, path_evals_last_jac;  // counters of the serial parts
  long boundary_evals;

  go_task_kind task;      // current parallel loop
  const double* task_zs;  // its scaled point
  double* task_out;       // its output array

  void* mem;              // the single allocation all arrays above are carved from
  char err[256];          // reason of the last failure
};

// worker context
static inline void* go_nlp_ctx(const go_nlp* nlp, int w) {
  return nlp->prob.thread_ctx ? nlp->prob.thread_ctx[w] : 0;
}

// trapezoidal weight of node k
static inline double go_nlp_weight(const go_nlp* nlp, int k) {
  return (k == 0 || k == nlp->N - 1) ? 0.5 : 1.0;
}

// finite-difference step in scaled variables: cbrt(eps) max(1, |zs|)
static inline double go_fd_step(double zs) {
  double a = zs < 0 ? -zs : zs;
  return 6.0554544523933395e-06 * (a > 1.0 ? a : 1.0);
}

// forward-difference step in scaled variables: sqrt(eps) max(1, |zs|)
static inline double go_fd_step_forward(double zs) {
  double a = zs < 0 ? -zs : zs;
  return 1.4901161193847656e-08 * (a > 1.0 ? a : 1.0);
}

// shared by both files
int go_nlp_node_g(go_nlp* nlp, int w, int k, const double* zs, double* g);
int go_nlp_node_L(go_nlp* nlp, int w, int k, const double* zs, double* L);
int go_nlp_eval_g_serial(go_nlp* nlp, int w, const double* zs, double* g);
int go_nlp_eval_f_serial(go_nlp* nlp, int w, const double* zs, double* f);
int go_nlp_boundary(go_nlp* nlp, int w, const double* zs, double* b);
void go_nlp_task(void* arg, int w, int item);
int go_nlp_check_status(go_nlp* nlp, int nitems, const char* what);
void go_nlp_defects(const go_nlp* nlp, const double* zs, double* g);
// the integrand's factor in the objective at zs: h = T / (N - 1) and outer()'s dJ/dI (1 without
// outer), from the integrand at every node; 0, or -1 with "WHO: ..." in nlp->err
int go_nlp_integrand_factor(go_nlp* nlp, const double* zs, const char* who, double* h,
                            double* dJdI);

#endif  // GAITSIM_OPTIM_GO_NLP_INTERNAL_H_
