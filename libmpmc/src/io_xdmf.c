/* The XDMF 3 file of an output series: a temporal collection of Polyvertex grids whose
 * geometry and attributes point into the HDF5 file ("run.h5:/snapshot_000000/position").
 * Rewritten after every snapshot through a temporary file and rename(), so that a run that
 * crashes still leaves a valid XDMF naming only complete snapshots. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io.h"

/* XML attribute/text escaping for names that come from the caller (set names). */
static void put_escaped(FILE *fp, const char *s) {
  for (; *s; ++s) {
    switch (*s) {
      case '&': fputs("&amp;", fp); break;
      case '<': fputs("&lt;", fp); break;
      case '>': fputs("&gt;", fp); break;
      case '"': fputs("&quot;", fp); break;
      default: fputc(*s, fp);
    }
  }
}

static void put_item(FILE *fp, const mpmc_output out, int k, int n, const mpmc_snap_field *f) {
  static const char *types[] = {"Float", "Int", "UChar"};
  static const int prec[] = {8, 4, 1};
  fprintf(fp, "        <DataItem Format=\"HDF\" NumberType=\"%s\" Precision=\"%d\" ",
          types[f->type], prec[f->type]);
  if (f->ncomp > 1)
    fprintf(fp, "Dimensions=\"%d %d\">", n, f->ncomp);
  else
    fprintf(fp, "Dimensions=\"%d\">", n);
  put_escaped(fp, out->h5ref);
  fprintf(fp, ":/snapshot_%06d/", k);
  put_escaped(fp, f->name);
  fputs("</DataItem>\n", fp);
}

int mpmc_xdmf_write(mpmc_output out) {
  mpmc_context ctx = out->sim->ctx;
  const size_t len = strlen(out->xdmfpath) + 5;
  char *tmp = malloc(len);
  MPMC_CHECK(tmp, ctx, MPMC_ERR_MEMORY, "cannot allocate a path");
  snprintf(tmp, len, "%s.tmp", out->xdmfpath);
  FILE *fp = fopen(tmp, "w");
  if (!fp) {
    const int err = MPMC_ERROR(ctx, MPMC_ERR_IO, "cannot write the XDMF file '%s'", tmp);
    free(tmp);
    return err;
  }
  fputs("<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
        "<Xdmf Version=\"3.0\">\n  <Domain>\n"
        "    <Grid Name=\"particles\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
        fp);
  for (int k = 0; k < out->nsnap; ++k) {
    const mpmc_snap *s = &out->snaps[k];
    fprintf(fp, "    <Grid Name=\"snapshot_%06d\" GridType=\"Uniform\">\n", k);
    fprintf(fp, "      <Time Value=\"%.17g\"/>\n", s->time);
    fprintf(fp,
            "      <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%d\" "
            "NodesPerElement=\"1\"/>\n",
            s->n);
    for (int i = 0; i < s->nfield; ++i) {
      const mpmc_snap_field *f = &s->fields[i];
      if (strcmp(f->name, "position") == 0) {
        fputs("      <Geometry GeometryType=\"XYZ\">\n", fp);
        put_item(fp, out, k, s->n, f);
        fputs("      </Geometry>\n", fp);
        continue;
      }
      /* stress is Voigt-ordered (xx yy zz yz xz xy), not XDMF's Tensor6 order, so it is
       * declared a 6-component Matrix */
      const char *atype = f->ncomp == 1 ? "Scalar" : f->ncomp == 3 ? "Vector" : "Matrix";
      fputs("      <Attribute Name=\"", fp);
      put_escaped(fp, f->name);
      fprintf(fp, "\" AttributeType=\"%s\" Center=\"Node\">\n", atype);
      put_item(fp, out, k, s->n, f);
      fputs("      </Attribute>\n", fp);
    }
    fputs("    </Grid>\n", fp);
  }
  fputs("    </Grid>\n  </Domain>\n</Xdmf>\n", fp);
  int bad = ferror(fp);
  bad |= fflush(fp) != 0;
  bad |= fsync(fileno(fp)) != 0;
  bad |= fclose(fp) != 0;
  if (bad || rename(tmp, out->xdmfpath) != 0) {
    remove(tmp);
    const int err = MPMC_ERROR(ctx, MPMC_ERR_IO, "cannot write the XDMF file '%s'", out->xdmfpath);
    free(tmp);
    return err;
  }
  free(tmp);
  return MPMC_SUCCESS;
}
