;;> \procedure{(set-process-name! name)} Names this process for ps and
;;> top (cut to 15 bytes): an address space is murdoch-UID.
;;> \procedure{(set-parent-death-signal! signal)} Has the kernel send
;;> \var{signal} to this process when the thread that forked it ends.
;;> Both answer #f when the kernel refuses.  Body: process.stub.
(define-library (murdoch sys process)
  (export set-process-name! set-parent-death-signal!)
  (include-shared "process"))
