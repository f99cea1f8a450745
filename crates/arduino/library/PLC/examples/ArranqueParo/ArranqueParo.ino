// Arranque y paro con autorretención, escrito a mano al estilo del S7-200 con PLC.h:
// Marcha (I0.0) enclava el motor (Q0.0), Paro (I0.1) lo corta; la lámpara (Q0.1) se
// enciende cuando el motor lleva 2 s en marcha; C0 cuenta los arranques y al tercero
// enciende Q0.2, hasta que I0.2 lo pone a cero. El mismo programa en AWL:
//
//   NETWORK 1  LD I0.0   O Q0.0   AN I0.1   = Q0.0
//   NETWORK 2  LD Q0.0   TON T37, +20
//   NETWORK 3  LD T37    = Q0.1
//   NETWORK 4  LD Q0.0   LD I0.2   CTU C0, +3
//   NETWORK 5  LD C0     = Q0.2
//   NETWORK 6  LD SM0.5  A Q0.0    = Q0.3      (parpadea mientras el motor marcha)
#include <PLC.h>

PLC_TIMER(37);   // T37: 100 ms
PLC_COUNTER(0);  // C0

void setup() { setupPLC(); }

void loop() {
    scanPLC();
    LD(I0_0);
    O(Q0_0);
    AN(I0_1);
    OUT(Q0_0);

    LD(Q0_0);
    TON(T37, 20);

    LD(T37);
    OUT(Q0_1);

    LD(Q0_0);
    LD(I0_2);
    CTU(C0, 3);

    LD(C0);
    OUT(Q0_2);

    LD(SM0_5);
    A(Q0_0);
    OUT(Q0_3);
}
