// go_jacobian.h: derivatives of the collocation NLP (go_collocation.h), in the solver's scaling.
//
// Constraint Jacobian, triplet form, no duplicate (row, column) pairs, entries in this order:
//   defects  for k = 0..N-2, i = 0..nx-1: x_{k,i}, x_{k+1,i}, xdot_{k,i}, xdot_{k+1,i}, [T]
//            (analytic: the defects are linear in z, bilinear with a free T)
//   path     for k = 0..N-1: the declared node pattern in compressed-column order
//            (analytic columns from path_jac; the others by central differences in which the
//            columns of one colour group, sharing no row, are perturbed together: 2 path
//            evaluations per group and node; step cbrt(eps) max(1, |z~_j|) in scaled variables)
//   boundary the declared pattern in compressed-column order over [z_0 | z_{N-1} | T]
//            (central differences, 2 boundary evaluations per column; T entries only if free)
// With GO_JAC_DENSE the same pattern is filled instead by central differences of the whole
// constraint vector over every variable (2 n full evaluations, 2 n N path evaluations): the
// baseline of Lin, Walter & Pandy 2018.
#ifndef GAITSIM_OPTIM_GO_JACOBIAN_H_
#define GAITSIM_OPTIM_GO_JACOBIAN_H_

#include "optim/go_collocation.h"

// Jacobian pattern (C indices, nele_jac entries from go_nlp_sizes).
void go_nlp_jac_structure(const go_nlp* nlp, int* irow, int* jcol);

// Jacobian values at the scaled point zs, in pattern order. 0, or -1 (go_nlp_last_error).
int go_nlp_eval_jac(go_nlp* nlp, const double* zs, double* vals);

// Objective gradient (n) at zs: integrand gradients per node (analytic or central differences
// over integrand_vars), T column analytic through the trapezoidal weights and outer().
// With GO_JAC_DENSE: central differences of the whole objective over every variable.
int go_nlp_eval_grad_f(go_nlp* nlp, const double* zs, double* grad);

// Gauss-Newton Hessian of the Lagrangian, for Ipopt's exact-Hessian mode: the diagonal (n) of
// obj_factor times the Hessian of the objective, from integrand_hess,
//   d2J/dz~_j^2 = dJ/dI h w_k d2L_k/dz_kj^2 z_scale_j^2 / obj_scale,
// and 0 in the T column. The constraints' curvature (the lambda terms) and outer()'s own curvature
// are left out: exact for a tracking objective (squares of variables) under linear constraints,
// the constrained Gauss-Newton method otherwise (Bock's generalised Gauss-Newton), which converges
// fast when the tracking residuals and multipliers are small. 0, or -1 without integrand_hess or
// when a callback fails (go_nlp_last_error).
int go_nlp_eval_hess_diag(go_nlp* nlp, const double* zs, double obj_factor, double* diag);
int go_nlp_has_hess_diag(const go_nlp* nlp);

// choose sparse (default) or dense (baseline) finite differences
void go_nlp_set_jac_mode(go_nlp* nlp, go_jac_mode mode);

// number of column groups of the path pattern (finite-difference colours, analytic columns
// excluded): a sparse Jacobian costs 2 * groups * N path evaluations
int go_nlp_path_groups(const go_nlp* nlp);

#endif  // GAITSIM_OPTIM_GO_JACOBIAN_H_
