// cgalref_svd.hpp -- the SVD CGAL's Monge_via_jet_fitting uses in
// test_cgal_reference and bench_fit.
//
// CGAL's default is Eigen's JacobiSVD (CGAL::Eigen_svd), enabled when the
// target links CGAL::Eigen3_support (tests/cgalref.cmake does that when
// libeigen3-dev is installed).  Without Eigen, Monge_via_jet_fitting has no
// default SvdTraits, so this header supplies a model of CGAL's SvdTraits
// concept on GSL's Golub-Kahan SVD: same least-squares solution for the
// full-rank systems the reference test compares (bench_fit says which SVD
// the CGAL side used).  Without Eigen, CGAL's PCA and Weingarten
// diagonalisation (Default_diagonalize_traits) also fall back to CGAL's
// Diagonalize_traits, a Jacobi that stops at 1e-5 relative (measured: 6e-2
// differences in c0 of interpolated 4-jets); so for double we specialise it
// on GSL's symmetric eigen-solver, as accurate as Eigen's, which is what
// CGAL uses in its default (Eigen) configuration.
#ifndef JF_CGALREF_SVD_HPP
#define JF_CGALREF_SVD_HPP

#include <array>
#include <vector>

#include <gsl/gsl_eigen.h>
#include <gsl/gsl_linalg.h>

#include <CGAL/Default_diagonalize_traits.h>

#ifndef CGAL_EIGEN3_ENABLED
namespace CGAL {
template <unsigned int dim> class Default_diagonalize_traits<double, dim> {
  public:
    typedef std::array<double, dim> Vector;
    typedef std::array<double, dim * dim> Matrix;
    typedef std::array<double, dim *(dim + 1) / 2> Covariance_matrix;

    // Eigenvalues ascending; eigenvector i at eigenvectors[dim*i..].
    static bool diagonalize_selfadjoint_covariance_matrix(
        const Covariance_matrix &cov, Vector &eigenvalues, Matrix &eigenvectors)
    {
        double a[dim * dim], e[dim], v[dim * dim];
        std::size_t k = 0;
        for (unsigned i = 0; i < dim; i++)  // upper triangle, row by row
            for (unsigned j = i; j < dim; j++, k++)
                a[i * dim + j] = a[j * dim + i] = cov[k];
        gsl_matrix_view A = gsl_matrix_view_array(a, dim, dim);
        gsl_matrix_view V = gsl_matrix_view_array(v, dim, dim);
        gsl_vector_view E = gsl_vector_view_array(e, dim);
        gsl_eigen_symmv_workspace *w = gsl_eigen_symmv_alloc(dim);
        int rc = w ? gsl_eigen_symmv(&A.matrix, &E.vector, &V.matrix, w) : -1;
        if (w) gsl_eigen_symmv_free(w);
        if (rc != 0) return false;
        gsl_eigen_symmv_sort(&E.vector, &V.matrix, GSL_EIGEN_SORT_VAL_ASC);
        for (unsigned i = 0; i < dim; i++) {
            eigenvalues[i] = e[i];
            for (unsigned j = 0; j < dim; j++)
                eigenvectors[dim * i + j] = v[j * dim + i];
        }
        return true;
    }
    static bool diagonalize_selfadjoint_covariance_matrix(
        const Covariance_matrix &cov, Vector &eigenvalues)
    {
        Matrix m;
        return diagonalize_selfadjoint_covariance_matrix(cov, eigenvalues, m);
    }
    static bool extract_largest_eigenvector_of_covariance_matrix(
        const Covariance_matrix &cov, Vector &normal)
    {
        Vector e;
        Matrix m;
        if (!diagonalize_selfadjoint_covariance_matrix(cov, e, m)) return false;
        for (unsigned j = 0; j < dim; j++) normal[j] = m[dim * (dim - 1) + j];
        return true;
    }
};
} // namespace CGAL
#endif

#include <CGAL/Simple_cartesian.h>
#include <CGAL/Monge_via_jet_fitting.h>

namespace jf_cgalref {

struct Gsl_svd {
    typedef double FT;
    struct Vector {
        std::vector<double> v;
        explicit Vector(std::size_t n) : v(n, 0.0) {}
        void set(std::size_t i, double x) { v[i] = x; }
        double operator()(std::size_t i) const { return v[i]; }
        double *vector() { return v.data(); }
        std::size_t size() const { return v.size(); }
    };
    struct Matrix {
        std::size_t r, c;
        std::vector<double> m;
        Matrix(std::size_t rows, std::size_t cols)
            : r(rows), c(cols), m(rows * cols, 0.0) {}
        void set(std::size_t i, std::size_t j, double x) { m[i * c + j] = x; }
        double operator()(std::size_t i, std::size_t j) const
        { return m[i * c + j]; }
    };
    // Least-squares solution of M X = B stored in B; returns
    // sigma_max / sigma_min as CGAL::Eigen_svd does.  rows >= cols (CGAL's
    // precondition N >= N_n).
    static FT solve(const Matrix &M, Vector &B)
    {
        std::vector<double> a(M.m), vv(M.c * M.c), s(M.c), w(M.c), x(M.c);
        gsl_matrix_view A = gsl_matrix_view_array(a.data(), M.r, M.c);
        gsl_matrix_view V = gsl_matrix_view_array(vv.data(), M.c, M.c);
        gsl_vector_view S = gsl_vector_view_array(s.data(), M.c);
        gsl_vector_view W = gsl_vector_view_array(w.data(), M.c);
        gsl_vector_view X = gsl_vector_view_array(x.data(), M.c);
        gsl_vector_view b = gsl_vector_view_array(B.v.data(), M.r);
        gsl_linalg_SV_decomp(&A.matrix, &V.matrix, &S.vector, &W.vector);
        gsl_linalg_SV_solve(&A.matrix, &V.matrix, &S.vector, &b.vector,
                            &X.vector);
        for (std::size_t i = 0; i < M.c; i++) B.v[i] = x[i];
        return s[0] / s[M.c - 1];
    }
};

typedef CGAL::Simple_cartesian<double> Kernel;
typedef Kernel::Point_3 Point;
#ifdef CGAL_EIGEN3_ENABLED
typedef CGAL::Monge_via_jet_fitting<Kernel> Monge_fitting;
static const char *const cgal_svd_name = "Eigen JacobiSVD (CGAL default)";
#else
typedef CGAL::Monge_via_jet_fitting<Kernel, Kernel, Gsl_svd> Monge_fitting;
static const char *const cgal_svd_name =
    "GSL SV_decomp and GSL symmv diagonalisation (no Eigen found)";
#endif
typedef Monge_fitting::Monge_form Monge_form;

} // namespace jf_cgalref

#endif
