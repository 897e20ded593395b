;;; The libraries as layers: each imports only from its own layer and
;;; those below, and no import goes round in a cycle.  The order of the
;;; layers is written here, once, by folder; README's "The shape" follows
;;; it, and names every library.
(import (scheme base) (scheme read) (scheme file) (scheme write) (scheme cxr)
        (srfi 1) (chibi test)
        (only (chibi filesystem) directory-files file-directory?)
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
          (offers holding) waiting life-cycle steps detached status)
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

(define (imports form)
  (append-map (lambda (decl)
                (if (and (pair? decl) (eq? (car decl) 'import))
                    (map import-set-library (cdr decl))
                    '()))
              (cddr form)))

(define (ours? name) (and (pair? name) (eq? (car name) 'murdoch)))

;; Every .sld under dir, in its folders too.
(define (sld-files dir)
  (append-map (lambda (f)
                (let ((path (string-append dir "/" f)))
                  (cond ((member f '("." "..")) '())
                        ((file-directory? path) (sld-files path))
                        ((text-contains? f ".sld") (list path))
                        (else '()))))
              (directory-files dir)))

(define library-files
  (cons (tool-path "lib/murdoch.sld") (sld-files (tool-path "lib/murdoch"))))

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

;; How README's shape table names a library: its path under lib/murdoch/,
;; `wire/frame`, or `(murdoch)`.
(define (table-name name)
  (if (null? (cdr name))
      "(murdoch)"
      (let loop ((parts (cddr name)) (path (symbol->string (cadr name))))
        (if (null? parts)
            path
            (loop (cdr parts) (string-append path "/" (symbol->string (car parts))))))))

;; The second cells of the rows of README's "The shape" table.
(define shape-library-cells
  (let loop ((lines (read-lines (tool-path "README.md"))) (in? #f) (cells '()))
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

;; The names the top-level forms of the files a library form includes
;; define, beside file: an umbrella's own procedures.
(define (own-definitions file form)
  (let ((dir (substring file 0 (- (string-length file)
                                  (string-length (last (string-split file #\/)))))))
    (append-map
     (lambda (decl)
       (if (and (pair? decl) (eq? (car decl) 'include))
           (filter-map (lambda (x)
                         (and (pair? x) (memq (car x) '(define define-syntax))
                              (if (pair? (cadr x)) (car (cadr x)) (cadr x))))
                       (call-with-input-file (string-append dir (cadr decl))
                         (lambda (in)
                           (let loop ((acc '()))
                             (let ((x (read in)))
                               (if (eof-object? x) (reverse acc) (loop (cons x acc))))))))
           '()))
     (cddr form))))

;; The families whose users import them as one, by their umbrellas.
(define families '(sys wire code robot remote pubsub task cli))

;; remote's and task's umbrellas are selections, what the layers above
;; import (see lib/murdoch/remote.scm and lib/murdoch/task.sld): their
;; members share more among themselves, the calls' and connections'
;; insides, a task's records and its waiters', which they leave out.
(define selections '(remote task))

;; What remote's umbrella passes on from the families below it: the
;; remote errors and the locks that the thesis's remote layer offers.
(define passed-on '((remote remote-error? remote-error-uid remote-error-message
                            remote-timeout-error? remote-unreachable-error?
                            remote-raised-error? remote-protocol-error?
                            undo-on-raise with-lock)))

;; How family's umbrella drifts from its members, the libraries in its
;; folder: (FAMILY missing NAME ...) for their exports it leaves out (but
;; for a selection), (FAMILY extra NAME ...) for exports no member, nor
;; it, defines.
(define (umbrella-drift family)
  (let* ((folder (tool-path (string-append "lib/murdoch/" (symbol->string family))))
         (file (string-append folder ".sld"))
         (form (library-form file))
         (members (append-map (lambda (f) (exports (library-form f)))
                              (sld-files folder)))
         (own (append (own-definitions file form)
                      (cond ((assq family passed-on) => cdr) (else '()))))
         (missing (if (memq family selections)
                      '()
                      (lset-difference eq? members (exports form))))
         (extra (lset-difference eq? (exports form) (append members own))))
    (append (if (pair? missing) (list (cons* family 'missing missing)) '())
            (if (pair? extra) (list (cons* family 'extra extra)) '()))))

(test-begin "layers")

(test "README's shape table names every library" '()
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

(test "each family's umbrella exports what its members export" '()
  (append-map umbrella-drift families))

(test-end)
(test-exit)
