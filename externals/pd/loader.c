/* loader.c -- the setup routine of one loader binary (membrane~.pd_linux,
 * contact~.pd_linux, ictus.pd_linux). All the code lives in libictus_pd.so,
 * found through RPATH $ORIGIN, so that both classes exist once whichever binary
 * Pd loads first; ICTUS_LOADER_SETUP names the setup function Pd looks for. */
#include "ictus_pd.h"

ICTUS_EXPORT void ICTUS_LOADER_SETUP(void);

void ICTUS_LOADER_SETUP(void)
{
    ictus_pd_setup();
}
