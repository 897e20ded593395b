;;; The libraries as layers: each imports only from its own layer and
;;; those below, no import goes round in a cycle, a library of another
;;; family imports a family's umbrella, never its members, and each
;;; umbrella exports only what is used above it.  The order of the layers
;;; is written here, once, by folder; docs/architecture.md's "The shape"
;;; follows it, and names every library.
(import (scheme base) (scheme read) (scheme file) (scheme write) (scheme cxr)
        (srfi 1) (chibi test)
        (only (chibi string) string-split)
        (murdoch testing harness))

;; Bottom to top: each family's folder under lib/murdoch/, or a library
;; of its own there, and `murdoch` for (murdoch) itself.  Inside a folder
;; any order will do, but where one is given, (FOLDER SUBLAYER ...), bottom
;; to top; a family's umbrella, (murdoch FOLDER), is above all its members.
(define layers
  '(sys lab wire code robot
    (remote aspace (connection worker call) group serve proxy delivery)
    (pubsub messaging monitor)
    (task (assign progress metric takers) team (pose-task running) record rank
          (offers holding) waiting life-cycle steps detached status parts)
    murdoch cli view testing))

(define (layer-folder layer) (if (pair? layer) (car layer) layer))

;; (FOLDER-INDEX . SUBLAYER-INDEX) of a library name, or #f: the sublayer
;; is 0 where its folder gives no order, and past them all for the umbrella.
(define (place-of name)
  (let* ((parts (cdr name))
         (folder (if (null? parts) 'murdoch (car parts)))
         (i (list-index (lambda (layer) (eq? (layer-folder layer) folder)) layers)))
    (and i
         (let ((layer (list-ref layers i)))
           (cond ((or (null? parts) (null? (cdr parts))) (cons i 1000))
                 ((not (pair? layer)) (cons i 0))
                 (else
                  (let ((j (list-index (lambda (sub)
                                         (if (pair? sub)
                                             (memq (cadr parts) sub)
                                             (eq? sub (cadr parts))))
                                       (cdr layer))))
                    (and j (cons i j)))))))))

(define (below? a b)
  (or (< (car a) (car b)) (and (= (car a) (car b)) (<= (cdr a) (cdr b)))))

;; The define-library form of file.
(define (library-form file)
  (call-with-input-file file read))

;; The library names an import set names, inside only, except, rename and
;; prefix.
(define (import-set-library set)
  (if (memq (car set) '(only except rename prefix))
      (import-set-library (cadr set))
      set))

(define (import-sets form)
  (append-map (lambda (decl)
                (if (and (pair? decl) (eq? (car decl) 'import)) (cdr decl) '()))
              (cddr form)))

(define (imports form) (map import-set-library (import-sets form)))

(define (ours? name) (and (pair? name) (eq? (car name) 'murdoch)))

(define library-files
  (cons (tool-path "lib/murdoch.sld") (files-under (tool-path "lib/murdoch") ".sld")))

;; (name . imports of ours), for every library.
(define graph
  (map (lambda (file)
         (let ((form (library-form file)))
           (cons (cadr form) (filter ours? (imports form)))))
       library-files))

;; The libraries on a path of imports from name back to name, or #f.  A
;; library already walked from leads back to name no more the second time.
(define (cycle-from name)
  (let ((seen '()))
    (let walk ((here name) (path '()))
      (cond ((and (pair? path) (equal? here name)) (reverse (cons here path)))
            ((member here seen) #f)
            (else (set! seen (cons here seen))
                  (any (lambda (next) (walk next (cons here path)))
                       (cond ((assoc here graph) => cdr) (else '()))))))))

;; How docs/architecture.md's shape table names a library: its path under lib/murdoch/,
;; `wire/frame`, or `(murdoch)`.
(define (table-name name)
  (if (null? (cdr name))
      "(murdoch)"
      (let loop ((parts (cddr name)) (path (symbol->string (cadr name))))
        (if (null? parts)
            path
            (loop (cdr parts) (string-append path "/" (symbol->string (car parts))))))))

;; The second cells of the rows of docs/architecture.md's "The shape" table.
(define shape-library-cells
  (let loop ((lines (read-lines (tool-path "docs/architecture.md"))) (in? #f) (cells '()))
    (cond ((null? lines) cells)
          ((string=? (car lines) "## The shape") (loop (cdr lines) #t cells))
          ((and in? (text-contains? (car lines) "## ")) cells)
          ((and in? (> (string-length (car lines)) 0)
                (char=? (string-ref (car lines) 0) #\|))
           (loop (cdr lines) in?
                 (cons (caddr (string-split (car lines) #\|)) cells)))
          (else (loop (cdr lines) in? cells)))))

;; The names a define-library form exports, (rename A B) as B.
(define (exports form)
  (append-map (lambda (decl)
                (if (and (pair? decl) (eq? (car decl) 'export))
                    (map (lambda (x) (if (pair? x) (caddr x) x)) (cdr decl))
                    '()))
              (cddr form)))

(define (file-forms file)
  (call-with-input-file file
    (lambda (in)
      (let loop ((acc '()))
        (let ((x (read in)))
          (if (eof-object? x) (reverse acc) (loop (cons x acc))))))))

;; The files of a library: its .sld and those it includes, beside it.
(define (library-source-files file form)
  (let ((dir (substring file 0 (- (string-length file)
                                  (string-length (last (string-split file #\/)))))))
    (cons file
          (append-map (lambda (decl)
                        (if (and (pair? decl) (eq? (car decl) 'include))
                            (map (lambda (f) (string-append dir f)) (cdr decl))
                            '()))
                      (cddr form)))))

;; The names the top-level forms of the files a library includes define:
;; an umbrella's own procedures.
(define (own-definitions file form)
  (append-map
   (lambda (f)
     (filter-map (lambda (x)
                   (and (pair? x) (memq (car x) '(define define-syntax))
                        (if (pair? (cadr x)) (car (cadr x)) (cadr x))))
                 (file-forms f)))
   (cdr (library-source-files file form))))

;; Every symbol the forms of files hold, quoted ones too; read once.
(define symbols-read '())
(define (symbols-in files)
  (cond
   ((assoc files symbols-read) => cdr)
   (else
    (let ((symbols (let walk ((x (append-map file-forms files)) (acc '()))
                     (cond ((symbol? x) (cons x acc))
                           ((pair? x) (walk (cdr x) (walk (car x) acc)))
                           ((vector? x) (walk (vector->list x) acc))
                           (else acc)))))
      (set! symbols-read (cons (cons files symbols) symbols-read))
      symbols))))

(define (library-file name)
  (find (lambda (file) (equal? (cadr (library-form file)) name)) library-files))

;; The family of a library: its folder, or its own name for (murdoch),
;; (murdoch lab) and the like.
(define (family name)
  (if (null? (cdr name)) 'murdoch (cadr name)))

;; The families with libraries of their own in a folder, and an umbrella.
(define families
  (filter (lambda (f)
            (and (library-file (list 'murdoch f))
                 (any (lambda (name) (and (pair? (cdr name)) (pair? (cddr name))
                                          (eq? (cadr name) f)))
                      (map car graph))))
          (delete-duplicates (map (lambda (entry) (family (car entry))) graph))))

;; What remote's umbrella passes on from the families below it: the
;; remote errors and the locks that the thesis's remote layer offers.
(define passed-on '((remote remote-error? remote-error-uid remote-error-message
                            remote-timeout-error? remote-unreachable-error?
                            remote-raised-error? remote-protocol-error?
                            undo-on-raise with-lock)))

;; The command, above every family: bin/murdoch.scm's imports and symbols.
(define command-file (tool-path "bin/murdoch.scm"))
(define command-imports
  (append-map (lambda (x) (if (and (pair? x) (eq? (car x) 'import)) (cdr x) '()))
              (file-forms command-file)))

;; Each library, and the command: (NAME IMPORT-SETS SYMBOLS), SYMBOLS
;; those of its source, read once.
(define users
  (cons (list '(command) command-imports (symbols-in (list command-file)))
        (map (lambda (file)
               (let ((form (library-form file)))
                 (list (cadr form) (import-sets form)
                       (symbols-in (library-source-files file form)))))
             library-files)))

;; Whether name, exported by umbrella, is used above its family: named in
;; an (only ...) import of it, or in the source of a library (or the
;; command) that imports all of it.
(define (used-above? umbrella name)
  (any (lambda (user)
         (and (or (equal? (car user) '(command))
                  (not (eq? (family (car user)) (family umbrella))))
              (any (lambda (set)
                     (and (equal? (import-set-library set) umbrella)
                          (if (eq? (car set) 'only)
                              (memq name (cddr set))
                              (memq name (caddr user)))))
                   (cadr user))))
       users))

;; How family's umbrella strays from a choice of its members' names:
;; (FAMILY unused NAME ...) for exports nothing above it uses, (FAMILY
;; extra NAME ...) for exports that no member, nor it, defines.
(define (umbrella-drift family)
  (let* ((name (list 'murdoch family))
         (file (library-file name))
         (form (library-form file))
         (members (append-map (lambda (entry)
                                (if (and (pair? (cdr (car entry))) (pair? (cddr (car entry)))
                                         (eq? (cadr (car entry)) family))
                                    (exports (library-form (library-file (car entry))))
                                    '()))
                              graph))
         (own (append (own-definitions file form)
                      (cond ((assq family passed-on) => cdr) (else '()))))
         (unused (remove (lambda (x) (or (memq x own) (used-above? name x)))
                         (exports form)))
         (extra (lset-difference eq? (exports form) (append members own))))
    (append (if (pair? unused) (list (cons* family 'unused unused)) '())
            (if (pair? extra) (list (cons* family 'extra extra)) '()))))

;; The names docs/reference.md gives a row, as tests/reference-test.scm
;; reads them: the first cell, `NAME` or `(NAME ARG ...)`.
(define reference-names
  (filter-map (lambda (line)
                (and (> (string-length line) 3) (string=? "| `" (substring line 0 3))
                     (let* ((cell (substring line 3 (string-length line)))
                            (cell (if (char=? (string-ref cell 0) #\()
                                      (substring cell 1 (string-length cell))
                                      cell))
                            (end (let loop ((i 0))
                                   (if (memv (string-ref cell i) '(#\space #\) #\`))
                                       i
                                       (loop (+ i 1))))))
                       (string->symbol (substring cell 0 end)))))
              (read-lines (tool-path "docs/reference.md"))))

;; The libraries of ours that received code's environment imports, as
;; lib/murdoch/code/sandbox.scm's sandbox-libraries names them, but for
;; the sandbox's own guarded versions of standard names.
(define sandbox-murdoch-libraries
  (let* ((forms (file-forms (tool-path "lib/murdoch/code/sandbox.scm")))
         (def (find (lambda (x) (and (pair? x) (eq? (car x) 'define)
                                     (eq? (cadr x) 'sandbox-libraries)))
                    forms)))
    (filter-map (lambda (set)
                  (and (ours? (import-set-library set))
                       (not (and (eq? (car set) 'rename)
                                 (equal? (import-set-library set)
                                         '(murdoch code sandbox))))
                       (import-set-library set)))
                (cadr (caddr def)))))

(test-begin "layers")

(test "docs/architecture.md's shape table names every library" '()
  (remove (lambda (name)
            (let ((quoted (string-append "`" (table-name name) "`")))
              (any (lambda (cell) (text-contains? cell quoted)) shape-library-cells)))
          (map car graph)))

(test "every library has a layer" '()
  (remove place-of (map car graph)))

(test "no library imports from a layer above its own" '()
  (append-map (lambda (entry)
                (filter-map (lambda (import)
                              (and (place-of import) (place-of (car entry))
                                   (not (below? (place-of import) (place-of (car entry))))
                                   (list (car entry) 'imports import)))
                            (cdr entry)))
              graph))

(test "no imports go round in a cycle" '()
  (filter-map cycle-from (map car graph)))

(test "no library imports another family's member; only its umbrella" '()
  (append-map (lambda (entry)
                (filter-map (lambda (import)
                              (and (ours? import) (pair? (cdr import)) (pair? (cddr import))
                                   (not (eq? (cadr import) (family (car entry))))
                                   (list (car entry) 'imports import)))
                            (cdr entry)))
              graph))

(test "each family's umbrella exports what the families above use of it" '()
  (append-map umbrella-drift families))

(test "docs/reference.md lists what (murdoch) exports, and nothing else" '(() ())
  (let ((exported (exports (library-form (tool-path "lib/murdoch.sld")))))
    (list (lset-difference eq? exported reference-names)
          (lset-difference eq? reference-names exported))))

(test "no Scheme file in lib/ is over 500 lines" '()
  (filter-map (lambda (f)
                (let ((n (length (text-lines (file-text f)))))
                  (and (> n 500) (list f n))))
              (files-under (tool-path "lib") ".scm")))

(test "received code reaches (murdoch) and no other library of ours" '((murdoch))
  sandbox-murdoch-libraries)

(test-end)
(test-exit)
