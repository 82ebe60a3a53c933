// go_hessian.h: a partitioned quasi-Newton Hessian of the collocation NLP's Lagrangian
// (Griewank & Toint 1982, "Partitioned variable metric updates for large structured optimization
// problems", Numer. Math. 39:119; the element form of LANCELOT).
//
// The Lagrangian of the collocation NLP (go_collocation.h) is a sum of node-local parts: the
// defects and the boundary rows used here are linear (their curvature is 0 for fixed T), so
//   L(z, lambda) = f(z) + sum_k sum_r lambda_{k,r} g_r(z_k)
// and its Hessian is block diagonal, one block per node. Within a node the problem declares
// ELEMENTS: groups of path rows with the node variables they depend on nonlinearly. The Hessian
// of element e at node k,
//   H_{k,e} = sum_{r in rows(e)} lambda_{k,r} d2 g_r / dz_{V(e)}^2,
// is approximated by a dense matrix B_{k,e} over V(e), updated at every new iterate by the
// symmetric rank-one formula (SR1, which can represent the indefinite curvature of constraint
// terms; Ipopt's inertia correction convexifies) from the element's own secant pair
//   s = z_k[V(e)] - z_k'[V(e)],   y = (J_k(z) - J_k(z'))[rows(e), V(e)]^T lambda[rows(e)]
// (J: the constraint Jacobian Ipopt has just evaluated at z, z' the previous iterate, both in the
// solver's scaling, lambda Ipopt's current multipliers). Every element learns its own curvature
// from every step, unlike one global limited-memory BFGS over all variables. The objective adds
// its exact diagonal (go_nlp_eval_hess_diag; the problem must provide integrand_hess).
//
// Measured (tests/test_collocation_pendulum.c): the pendulum swing-up converges in 9 iterations
// against 21 with Ipopt's L-BFGS. On the full-body tracking problem it does NOT help yet: the
// dual infeasibility grows to 1e15 within 20 iterations (damped BFGS instead of SR1, and
// mu_strategy adaptive, behave alike), so `gaitsim track` keeps L-BFGS as its default.
//
// The Hessian pattern (lower triangle, node-major) is the union of the element blocks plus every
// node variable's diagonal, and the T diagonal (0) when T is free.
#ifndef GAITSIM_OPTIM_GO_HESSIAN_H_
#define GAITSIM_OPTIM_GO_HESSIAN_H_

#include "optim/go_collocation.h"

// Elements of one node (the same for every node). A path row belongs to at most one element;
// rows in no element are treated as linear.
typedef struct {
  int n_elem;           // elements per node
  const int* row_ptr;   // rows of element e: rows[row_ptr[e] .. row_ptr[e+1])   (n_elem + 1)
  const int* rows;      // path rows (0 .. n_path-1)
  const int* var_ptr;   // variables of element e: vars[var_ptr[e] .. var_ptr[e+1]) (n_elem + 1)
  const int* vars;      // node variables (0 .. nz-1), strictly increasing within an element
  // optional, for the finite-difference Hessian (go_hess_create_fd); NULL: none / all
  const unsigned char* lin;  // per element variable (aligned with vars): 1 when the element's
                             // rows are jointly linear in the variables so marked (no curvature
                             // among them, e.g. the dynamics in qddot and the tendon forces)
  const unsigned char* fd_pairs;  // nz x nz: 0 where two finite-difference (non-analytic)
                                  // variables of one element are known to have no mixed curvature
                                  // (e.g. dofs on different branches of the kinematic tree)
} go_elements;

typedef struct go_hess go_hess;

// Build the Hessian for nlp with the given elements (copied). 0 and *out (free with
// go_hess_free), or -1 with the reason in err.
int go_hess_create(go_hess** out, go_nlp* nlp, const go_elements* el, char* err, int errsz);
void go_hess_free(go_hess* h);

// nonzeros of the lower triangle, and their pattern (C indices)
int go_hess_nnz(const go_hess* h);
void go_hess_structure(const go_hess* h, int* irow, int* jcol);

// Remember the constraint Jacobian values (go_nlp_eval_jac order) Ipopt evaluated at the scaled
// point x; the next go_hess_values at the same x uses them.
void go_hess_note_jacobian(go_hess* h, const double* x, const double* jac);

// Hessian values at x (scaled), objective factor and multipliers lambda (m, scaled): updates
// every element from the secant pair since the previous update (when x is new and the Jacobian at
// x has been noted), then writes obj_factor * objective diagonal + sum of the element blocks.
// 0, or -1 when x's Jacobian was not noted or the objective diagonal failed.
int go_hess_values(go_hess* h, const double* x, double obj_factor, const double* lambda,
                   double* vals);

// Exact Hessian by finite differences instead of secant updates (the element structure decides
// what is evaluated). With phi_k = sum_r lambda_{k,r} g_r(z_k) over the rows of the elements, in
// the solver's scaling, per node:
//   (A) pairs of finite-difference variables i, j (the columns without path_jac) sharing an element
//       (and allowed by fd_pairs): second differences of phi_k,
//       H_ii = (phi(+i) - 2 phi + phi(-i)) / h^2,  H_ij = (phi(+i+j) - phi(+i) - phi(+j) + phi) / h^2,
//       h = 1e-5 max(1, |z~|), one path evaluation per pair (one-sided: the pair formula reuses
//       phi(+i) and phi(+j) of the diagonal) and two per variable. The one-sided pair formula
//       errs by O(h) where the central one (two evaluations per pair) erred by O(h^2); with h
//       1e-5 instead of 1e-4 the worst entry of tests/test_hessian_fd.c is 9.8e-4 of its
//       column's largest (central, h 1e-4: 1.1e-4; one-sided at 3e-5: 3.0e-3, at 3e-6 rounding
//       takes over) for half the evaluations: the pairs are nearly all of them;
//   (B) a finite-difference variable i with an analytic column w of one element: forward
//       differences of the analytic partials (path_jac at z + h e_i, h = sqrt(eps) max(1, |z~|));
//   (C) analytic variables with curvature in some element (not `lin` there): central differences
//       of path_jac, the variables perturbed together in colour groups such that within any
//       element a group holds at most one (distance-1 colouring of "share an element where one
//       of them is not lin"); entries between two such variables averaged over both perturbations.
// The pairs are evaluated with their lower variable in the outer loop, so that consecutive
// evaluations share all but one perturbed variable (a problem may reuse work between them).
// Costs per node and Hessian: 1 + 2 n_fd + n_pairs path evaluations, 1 + n_fd + 2 n_colours
// path_jac calls (full body: 26 dofs -> n_fd 52; see docs/BENCHMARKS.md). The pattern holds only
// the entries these produce (structural zeros of lin x lin left out) and every diagonal. The
// objective adds its node Hessian when the problem gives one (integrand_hess_block, its mask's
// entries added to the pattern; e.g. a prediction's metabolic power), else its exact diagonal
// (go_nlp_eval_hess_diag) when the problem has one; otherwise the objective's curvature is left
// out. Either is scaled by obj_factor dJ/dI h w_k / obj_scale: outer()'s own curvature is left
// out (the cost of transport I / T with I = h sum w_k L_k has none). With a free T the defects'
// T x xdot curvature is left out.
// Rows in no element are taken as linear. Same arguments and results as go_hess_create.
// Measured (docs/BENCHMARKS.md, "Resolution"): 8468 Hessian entries per node of jw_fullbody and
// about 910 path evaluations per node and Hessian (tests/test_hessian_fd.c prints both); at N = 80
// about 3.4 s of CPU per Hessian on one core (5.9 s before go_gait reused its position stage,
// "The position stage reused"). From the trial's guess with Ipopt's monotone barrier from mu 0.1
// the steps are tiny (alpha 1e-3 - 1e-1) and inf_du grows to 1e5-1e9 within 30 iterations (the
// values are right: tests/test_hessian_fd.c); from an L-BFGS tracking solution with mu 1e-6 and
// mu-based bound multipliers it reaches Ipopt's acceptable level in about 50 iterations at N = 20,
// which `gaitsim track --refine` uses after an L-BFGS solve that stops short.
int go_hess_create_fd(go_hess** out, go_nlp* nlp, const go_elements* el, char* err, int errsz);

// counters: element updates done and skipped (tiny, non-finite or ill-conditioned pairs)
void go_hess_counts(const go_hess* h, long* updates, long* skipped);

#endif  // GAITSIM_OPTIM_GO_HESSIAN_H_
