/*
 * jointrom_slepc: the distributed offline stage of jointrom (docs/distributed.md).
 *
 * Reads a job folder written by `jointrom distributed` (PETSc binary, see
 * src/model/petsc.rs):
 *   Kii.petsc, Mii.petsc  the fixed-interface stiffness and mass (master DOF removed), AIJ;
 *   K.petsc               the whole stiffness (master free, the case's clamps), AIJ;
 *   R.petsc               the TVD right-hand sides B_u^T Q (n x p), dense.
 * and computes on PETSC_COMM_WORLD (any number of MPI ranks):
 *   1. the nev lowest fixed-interface modes, K_ii phi = omega^2 M_ii phi: SLEPc Krylov-Schur,
 *      generalized Hermitian (M_ii inner product), shift-and-invert with target 0
 *      (operator K_ii^-1 M_ii, the native path's inverse operator), the shifted system
 *      factored by MUMPS Cholesky;
 *   2. the multi-right-hand-side solve K Z = R: one MUMPS Cholesky of K, all p columns in one
 *      KSPMatSolve (MatMatSolve).
 * Writes into the output folder:
 *   modes.petsc    nev vectors (length n_i) one after another, M_ii-normalized by SLEPc;
 *   Z.petsc        the solution block, dense (PETSc's native dense format, values by rows);
 *   result.json    ranks, eigenvalues omega^2 ((rad/s)^2, %.17g: exact round trip), SLEPc's
 *                  relative residuals, iterations, wall time of each stage (s, MPI_Wtime).
 *
 * Usage: mpirun -n R jointrom_slepc -dir JOB -out OUT -nev NU [-tol 1e-12] [PETSc/SLEPc options]
 * Options of the eigen solve take the usual eps_/st_ prefixes; the TVD solve's KSP has prefix
 * tvd_. Build: scripts/dist.sh build (mpicc, pkg-config slepc).
 */
#include <slepceps.h>

/* Loads DIR/NAME as a matrix of type TYPE on PETSC_COMM_WORLD. */
static PetscErrorCode LoadMat(const char *dir, const char *name, MatType type, Mat *a)
{
  char        path[PETSC_MAX_PATH_LEN];
  PetscViewer v;

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/%s", dir, name));
  PetscCall(PetscViewerBinaryOpen(PETSC_COMM_WORLD, path, FILE_MODE_READ, &v));
  PetscCall(MatCreate(PETSC_COMM_WORLD, a));
  PetscCall(MatSetType(*a, type));
  PetscCall(MatLoad(*a, v));
  PetscCall(PetscViewerDestroy(&v));
  PetscFunctionReturn(0);
}

/* A binary viewer writing OUT/NAME without the .info side file. */
static PetscErrorCode OpenOutput(const char *out, const char *name, PetscViewer *v)
{
  char path[PETSC_MAX_PATH_LEN];

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/%s", out, name));
  PetscCall(PetscViewerCreate(PETSC_COMM_WORLD, v));
  PetscCall(PetscViewerSetType(*v, PETSCVIEWERBINARY));
  PetscCall(PetscViewerFileSetMode(*v, FILE_MODE_WRITE));
  PetscCall(PetscViewerBinarySetSkipInfo(*v, PETSC_TRUE));
  PetscCall(PetscViewerFileSetName(*v, path));
  PetscFunctionReturn(0);
}

/* Preonly + Cholesky by MUMPS on a KSP. */
static PetscErrorCode UseMumpsCholesky(KSP ksp)
{
  PC pc;

  PetscFunctionBeginUser;
  PetscCall(KSPSetType(ksp, KSPPREONLY));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCSetType(pc, PCCHOLESKY));
  PetscCall(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
  PetscFunctionReturn(0);
}

typedef struct {
  PetscInt   nev, nconv, its;
  PetscReal *lambda, *error;
  double     load_s, eps_s, write_modes_s, load_k_s, factor_s, solve_s, write_z_s;
  PetscInt   n_interior, n, p;
} Result;

/* Stage 1: the nev lowest modes of K_ii phi = lambda M_ii phi, written to OUT/modes.petsc. */
static PetscErrorCode EigenStage(const char *dir, const char *out, PetscReal tol, Result *r)
{
  Mat         kii, mii;
  EPS         eps;
  ST          st;
  KSP         ksp;
  Vec         x;
  PetscViewer v;
  double      t0;

  PetscFunctionBeginUser;
  t0 = MPI_Wtime();
  PetscCall(LoadMat(dir, "Kii.petsc", MATAIJ, &kii));
  PetscCall(LoadMat(dir, "Mii.petsc", MATAIJ, &mii));
  PetscCall(MatSetOption(kii, MAT_SPD, PETSC_TRUE));
  PetscCall(MatSetOption(mii, MAT_SPD, PETSC_TRUE));
  PetscCall(MatGetSize(kii, &r->n_interior, NULL));
  r->load_s = MPI_Wtime() - t0;

  PetscCall(EPSCreate(PETSC_COMM_WORLD, &eps));
  PetscCall(EPSSetOperators(eps, kii, mii));
  PetscCall(EPSSetProblemType(eps, EPS_GHEP));
  PetscCall(EPSSetType(eps, EPSKRYLOVSCHUR));
  PetscCall(EPSSetDimensions(eps, r->nev, PETSC_DEFAULT, PETSC_DEFAULT));
  PetscCall(EPSSetTolerances(eps, tol, 1000));
  PetscCall(EPSSetTarget(eps, 0.0));
  PetscCall(EPSSetWhichEigenpairs(eps, EPS_TARGET_MAGNITUDE));
  PetscCall(EPSGetST(eps, &st));
  PetscCall(STSetType(st, STSINVERT));
  PetscCall(STGetKSP(st, &ksp));
  PetscCall(UseMumpsCholesky(ksp));
  PetscCall(EPSSetFromOptions(eps));
  t0 = MPI_Wtime();
  PetscCall(EPSSolve(eps));
  r->eps_s = MPI_Wtime() - t0;
  PetscCall(EPSGetConverged(eps, &r->nconv));
  PetscCall(EPSGetIterationNumber(eps, &r->its));
  PetscCheck(r->nconv >= r->nev, PETSC_COMM_WORLD, PETSC_ERR_NOT_CONVERGED,
             "EPSSolve converged %" PetscInt_FMT " of %" PetscInt_FMT " modes", r->nconv, r->nev);

  t0 = MPI_Wtime();
  PetscCall(MatCreateVecs(kii, &x, NULL));
  PetscCall(OpenOutput(out, "modes.petsc", &v));
  for (PetscInt i = 0; i < r->nev; i++) {
    PetscScalar kr;
    PetscCall(EPSGetEigenpair(eps, i, &kr, NULL, x, NULL));
    r->lambda[i] = PetscRealPart(kr);
    PetscCall(EPSComputeError(eps, i, EPS_ERROR_RELATIVE, &r->error[i]));
    PetscCall(VecView(x, v));
  }
  PetscCall(PetscViewerDestroy(&v));
  r->write_modes_s = MPI_Wtime() - t0;
  PetscCall(VecDestroy(&x));
  PetscCall(EPSDestroy(&eps));
  PetscCall(MatDestroy(&kii));
  PetscCall(MatDestroy(&mii));
  PetscFunctionReturn(0);
}

/* Stage 2: K Z = R, one MUMPS Cholesky, all columns at once, written to OUT/Z.petsc. */
static PetscErrorCode SolveStage(const char *dir, const char *out, Result *r)
{
  Mat         k, rhs, z;
  KSP         ksp;
  PetscViewer v;
  double      t0;

  PetscFunctionBeginUser;
  t0 = MPI_Wtime();
  PetscCall(LoadMat(dir, "K.petsc", MATAIJ, &k));
  PetscCall(MatSetOption(k, MAT_SPD, PETSC_TRUE));
  PetscCall(LoadMat(dir, "R.petsc", MATDENSE, &rhs));
  PetscCall(MatGetSize(rhs, &r->n, &r->p));
  r->load_k_s = MPI_Wtime() - t0;

  PetscCall(KSPCreate(PETSC_COMM_WORLD, &ksp));
  PetscCall(KSPSetOptionsPrefix(ksp, "tvd_"));
  PetscCall(KSPSetOperators(ksp, k, k));
  PetscCall(UseMumpsCholesky(ksp));
  PetscCall(KSPSetFromOptions(ksp));
  t0 = MPI_Wtime();
  PetscCall(KSPSetUp(ksp));
  r->factor_s = MPI_Wtime() - t0;
  PetscCall(MatDuplicate(rhs, MAT_DO_NOT_COPY_VALUES, &z));
  t0 = MPI_Wtime();
  PetscCall(KSPMatSolve(ksp, rhs, z));
  r->solve_s = MPI_Wtime() - t0;

  t0 = MPI_Wtime();
  PetscCall(OpenOutput(out, "Z.petsc", &v));
  PetscCall(PetscViewerPushFormat(v, PETSC_VIEWER_NATIVE));
  PetscCall(MatView(z, v));
  PetscCall(PetscViewerPopFormat(v));
  PetscCall(PetscViewerDestroy(&v));
  r->write_z_s = MPI_Wtime() - t0;
  PetscCall(KSPDestroy(&ksp));
  PetscCall(MatDestroy(&z));
  PetscCall(MatDestroy(&rhs));
  PetscCall(MatDestroy(&k));
  PetscFunctionReturn(0);
}

/* OUT/result.json, written by rank 0. */
static PetscErrorCode WriteResult(const char *out, const Result *r, double total_s)
{
  char        path[PETSC_MAX_PATH_LEN];
  FILE       *fp;
  PetscMPIInt size;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/result.json", out));
  PetscCall(PetscFOpen(PETSC_COMM_WORLD, path, "w", &fp));
  PetscCall(PetscFPrintf(PETSC_COMM_WORLD, fp, "{\n  \"ranks\": %d,\n", (int)size));
  PetscCall(PetscFPrintf(PETSC_COMM_WORLD, fp, "  \"interior_dofs\": %" PetscInt_FMT ",\n  \"dofs\": %" PetscInt_FMT ",\n  \"rhs_columns\": %" PetscInt_FMT ",\n", r->n_interior, r->n, r->p));
  PetscCall(PetscFPrintf(PETSC_COMM_WORLD, fp, "  \"converged\": %" PetscInt_FMT ",\n  \"iterations\": %" PetscInt_FMT ",\n", r->nconv, r->its));
  PetscCall(PetscFPrintf(PETSC_COMM_WORLD, fp, "  \"eigenvalues\": ["));
  for (PetscInt i = 0; i < r->nev; i++) PetscCall(PetscFPrintf(PETSC_COMM_WORLD, fp, "%s%.17g", i ? ", " : "", (double)r->lambda[i]));
  PetscCall(PetscFPrintf(PETSC_COMM_WORLD, fp, "],\n  \"relative_errors\": ["));
  for (PetscInt i = 0; i < r->nev; i++) PetscCall(PetscFPrintf(PETSC_COMM_WORLD, fp, "%s%.3e", i ? ", " : "", (double)r->error[i]));
  PetscCall(PetscFPrintf(PETSC_COMM_WORLD, fp, "],\n  \"seconds\": {\"load_eigen\": %.6f, \"eigen\": %.6f, \"write_modes\": %.6f, ", r->load_s, r->eps_s, r->write_modes_s));
  PetscCall(PetscFPrintf(PETSC_COMM_WORLD, fp, "\"load_solve\": %.6f, \"factor\": %.6f, \"solve\": %.6f, \"write_solution\": %.6f, \"total\": %.6f}\n}\n", r->load_k_s, r->factor_s, r->solve_s, r->write_z_s, total_s));
  PetscCall(PetscFClose(PETSC_COMM_WORLD, fp));
  PetscFunctionReturn(0);
}

int main(int argc, char **argv)
{
  char      dir[PETSC_MAX_PATH_LEN], out[PETSC_MAX_PATH_LEN];
  PetscBool has_dir, has_out, has_nev;
  PetscReal tol = 1e-12;
  Result    r;
  double    t0;

  PetscCall(SlepcInitialize(&argc, &argv, NULL, "jointrom's distributed offline stage (docs/distributed.md)\n"));
  t0 = MPI_Wtime();
  PetscCall(PetscMemzero(&r, sizeof(r)));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-dir", dir, sizeof(dir), &has_dir));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-out", out, sizeof(out), &has_out));
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-nev", &r.nev, &has_nev));
  PetscCall(PetscOptionsGetReal(NULL, NULL, "-tol", &tol, NULL));
  PetscCheck(has_dir && has_out && has_nev, PETSC_COMM_WORLD, PETSC_ERR_USER, "usage: jointrom_slepc -dir JOB -out OUT -nev NU [-tol 1e-12]");
  PetscCheck(r.nev > 0, PETSC_COMM_WORLD, PETSC_ERR_USER, "-nev %" PetscInt_FMT ": need at least one mode", r.nev);
  PetscCall(PetscMalloc2(r.nev, &r.lambda, r.nev, &r.error));
  PetscCall(EigenStage(dir, out, tol, &r));
  PetscCall(SolveStage(dir, out, &r));
  PetscCall(WriteResult(out, &r, MPI_Wtime() - t0));
  PetscCall(PetscFree2(r.lambda, r.error));
  PetscCall(SlepcFinalize());
  return 0;
}
