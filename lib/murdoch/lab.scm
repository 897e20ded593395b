;;;; The lab file (docs/lab-file.md): who is in the lab and where.
;;
;; Every peer reads the same file, so the lab needs no registry: a uid
;; names an address space, and the file says where it listens.

(define-record-type lab
  (make-lab name directory settings aspaces clauses)
  lab?
  (name lab-name)
  (directory lab-directory)
  (settings lab-settings)
  (aspaces lab-aspaces)
  (clauses lab-clauses))

;;> The radius of the lab's robots in millimetres: its b14 clause's, or
;;> the simulator's B14's (room.scm).
(define (lab-robot-radius lab)
  (robot-radius (lab-clauses lab)))

;;> The lab file's top-level clause \scheme{(key ...)}, such as its
;;> \scheme{world}, or #f.
(define (lab-clause lab key)
  (clause key (lab-clauses lab)))

;;> One address space of the lab file.  \var{clauses} keeps the clauses that
;;> later layers read (robot, position, capabilities, load).
(define-record-type lab-aspace
  (make-lab-aspace uid index host port clauses)
  lab-aspace?
  (uid lab-aspace-uid)
  (index lab-aspace-index)
  (host lab-aspace-host)
  (port lab-aspace-port)
  (clauses lab-aspace-clauses))

(define (clause key clauses)
  (find (lambda (c) (and (pair? c) (eq? (car c) key))) clauses))

(define (clause-value key clauses default)
  (cond ((clause key clauses) => cadr) (else default)))

;;; Settings
;;
;; Every setting a lab file may give, in one table: its name, its
;; default, and its reader, which answers the value to use for what the
;; file wrote, or #f when that will not do, and what will.  Most take one
;; value; code and delivery take the rest of their clause.  read-lab reads
;; each once, and every place that needs one asks lab-setting.

(define (number-over zero what)
  (cons (lambda (x) (and (real? x) (> x zero) x)) what))

(define (whole-from low high what)
  (cons (lambda (x) (and (exact-integer? x) (<= low x high) x)) what))

(define (text what) (cons (lambda (x) (and (string? x) x)) what))

(define seconds (number-over 0 "a positive number of seconds"))
(define rate
  (cons (lambda (x) (and (real? x) (>= x 0) x)) "a number, 0 or more, per second"))
(define positive-count (whole-from 1 1000000000 "a positive whole number"))

;; A size: bytes, or a string of a number and K, M or G.
(define (size-bytes size)
  (cond ((and (exact-integer? size) (positive? size)) size)
        ((and (string? size) (> (string-length size) 1))
         (let* ((n (string-length size))
                (unit (assv (string-ref size (- n 1))
                            '((#\K . 1024) (#\M . 1048576) (#\G . 1073741824))))
                (number (string->number (substring size 0 (- n 1)))))
           (and unit number (positive? number) (exact (round (* number (cdr unit)))))))
        (else #f)))

(define (delivery-clause args)
  (cond ((equal? args '(broadcast)) args)
        ((and (pair? args) (eq? (car args) 'multicast) (pair? (cdr args))
              (string? (cadr args))
              (or (null? (cddr args))
                  (and (exact-integer? (car (cddr args))) (null? (cdr (cddr args))))))
         args)
        (else #f)))

(define settings-table
  `((port-base 7100 ,(whole-from 1 65535 "a port number"))
    (interface "127.0.0.1" ,(text "an IPv4 address, in quotes"))
    (key-file "murdoch.key" ,(text "a file name, in quotes"))
    (max-frame 1048576 ,positive-count)
    ;; Chibi's writer cuts what nests deeper than 10,000 (sendable.scm).
    (max-depth 4000 ,(whole-from 1 9000 "a whole number from 1 to 9000"))
    (timeout 5 ,seconds)
    ;; At a REPL a person waits, and Ctrl-C gives a call up: a robot's
    ;; motion there runs to its end (command.scm).
    (repl-timeout 600 ,seconds)
    (frame-timeout 5 ,seconds)
    (lease 30 ,seconds)
    (monitor-period 60 ,seconds)
    ;; A started task's components and their poser hear from each other
    ;; every heartbeat seconds (task.scm).
    (heartbeat 0.5 ,seconds)
    (max-attempts 3 ,positive-count)
    ;; A started task that finds too few capable robots free waits for
    ;; them or fails with not-enough-takers; its priority rises by aging
    ;; a second while it waits; a poser keeps at most max-waiting such
    ;; tasks (task.scm, docs/tasks.md).
    (when-robots-busy fail (,(lambda (x) (and (memq x '(fail wait)) x)) . "fail or wait"))
    (aging 0.1 ,rate)
    (max-waiting 100 ,positive-count)
    (max-connections 256 ,positive-count)
    (max-connections-per-host 64 ,positive-count)
    (heap-max "512M" (,size-bytes . "bytes, or a size in quotes such as \"512M\""))
    (code () (,(lambda (x) (and (every string? x) x)) . "file names, in quotes"))
    (delivery (broadcast) (,delivery-clause . "broadcast, or multicast \"GROUP\" [PORT]"))))

;; The clauses the simulator reads (docs/trip-protocol.md), and address
;; spaces.
(define other-clauses '(world simulator b14 aspace))

(define multi-valued '(code delivery))

;;> The value of setting \var{key} of the lab: what its file says, or the
;;> default (docs/lab-file.md).
(define (lab-setting lab key)
  (cond ((assq key (lab-settings lab)) => cdr)
        (else (error "lab-setting: no such setting" key))))

;; The settings of the clauses, every one of the table's, checked: an
;; error names the file, the clause and what is wrong.
(define (read-settings path clauses)
  (for-each (lambda (c) (check-clause path c)) clauses)
  (map (lambda (entry)
         (let ((c (clause (car entry) clauses)))
           (cons (car entry)
                 (if c
                     (setting-value path c entry)
                     ((car (car (cddr entry))) (cadr entry))))))
       settings-table))

(define (check-clause path c)
  (if (not (and (pair? c) (symbol? (car c)) (list? c)))
      (lab-file-error path c "a clause is (NAME VALUE ...)"))
  (if (not (or (assq (car c) settings-table) (memq (car c) other-clauses)))
      (lab-file-error path c (string-append "no such setting" (did-you-mean (car c))))))

(define (setting-value path c entry)
  (let* ((reader (car (cddr entry)))
         (multi? (memq (car entry) multi-valued))
         (value (cond (multi? ((car reader) (cdr c)))
                      ((and (pair? (cdr c)) (null? (cddr c))) ((car reader) (cadr c)))
                      (else #f))))
    (or value
        (lab-file-error path c (string-append (symbol->string (car c)) " takes "
                                              (cdr reader))))))

(define (did-you-mean name)
  (let ((near (find-nearest-edits (symbol->string name)
                                  (map (lambda (n) (symbol->string n))
                                       (append (map car settings-table) other-clauses)))))
    (if (and (pair? near) (<= (edit-distance (symbol->string name) (car near)) 3))
        (string-append "; did you mean " (car near) "?")
        "")))

;; Where each clause of the lab file being read starts: ((CLAUSE . LINE) ...),
;; by eq?, for its errors.
(define clause-lines (make-parameter '()))

(define (lab-file-error path c why)
  (let ((line (assq c (clause-lines))))
    (error (string-append path (if line (string-append ":" (number->string (cdr line))) "")
                          ": " (clause-text c) ": " why))))

(define (clause-text c)
  (let ((out (open-output-string)))
    (write c out)
    (get-output-string out)))

;;> The clause \scheme{(key ...)} of an address space, or #f.
(define (lab-aspace-clause a key)
  (clause key (lab-aspace-clauses a)))

;;> The lab's port base: MURDOCH_PORT_BASE, else its port-base.
(define (lab-port-base lab)
  (settings-port-base (lab-settings lab)))

(define (settings-port-base settings)
  (cond ((get-environment-variable "MURDOCH_PORT_BASE") => string->number)
        (else (cdr (assq 'port-base settings)))))

;;> A port for a guest, an address space the file does not name (a REPL
;;> that joins the lab): one of port-base + 150 to + 199, by process id.
(define (lab-guest-port lab)
  (+ (lab-port-base lab) 150 (modulo (current-process-id) 50)))

;;> Reads the lab file at \var{path}.  Errors name the file and the fault.
(define (read-lab path)
  (let* ((read (guard (e (#t (error "cannot read the lab file" path
                                   (condition-message e))))
                 (call-with-input-file path read-lab-form)))
         (form (car read)))
    (if (not (and (pair? form) (eq? (car form) 'lab) (pair? (cdr form))
                  (symbol? (cadr form)) (list? (cddr form))))
        (error "a lab file holds one (lab NAME CLAUSE ...) form" path))
    (parameterize ((clause-lines (cdr read)))
      (parse-lab path form))))

;; The file's (lab NAME CLAUSE ...) form, and the line each clause starts
;; on: (FORM (CLAUSE . LINE) ...).  Anything else is read whole, for
;; read-lab to refuse.
(define (read-lab-form in)
  (skip-blanks in)
  (if (not (eqv? (peek-char in) #\())
      (list (read in))
      (begin
        (read-char in)
        (let loop ((items '()) (lines '()))
          (skip-blanks in)
          (cond ((eof-object? (peek-char in)) (list (reverse items)))
                ((eqv? (peek-char in) #\)) (read-char in) (cons (reverse items) lines))
                (else (let* ((line (port-line in))
                             (item (read in)))
                        (loop (cons item items) (cons (cons item line) lines)))))))))

;; Skips white space and ; comments.
(define (skip-blanks in)
  (let ((c (peek-char in)))
    (cond ((eof-object? c) c)
          ((char-whitespace? c) (read-char in) (skip-blanks in))
          ((char=? c #\;) (read-line in) (skip-blanks in))
          (else c))))

(define (parse-lab path form)
  (let* ((clauses (cddr form))
         (settings (read-settings path clauses))
         (base (settings-port-base settings))
         (interface (cdr (assq 'interface settings)))
         (lab (make-lab (cadr form) (path-directory path) settings
                        (let loop ((cs clauses) (i 0) (acc '()))
                          (cond
                           ((null? cs) (reverse acc))
                           ((and (pair? (car cs)) (eq? (caar cs) 'aspace))
                            (loop (cdr cs) (+ i 1)
                                  (cons (parse-aspace path (car cs) i base interface)
                                        acc)))
                           (else (loop (cdr cs) i acc))))
                        clauses)))
    (check-lab path lab)
    (check-room path clauses)
    lab))

;; What no one clause shows: two address spaces of one name, two things
;; on one port, a code file that is not there.
(define (check-lab path lab)
  (let ((uids (map lab-aspace-uid (lab-aspaces lab))))
    (cond ((find-duplicate uids)
           => (lambda (uid)
                (lab-file-error path (list 'aspace uid) "two address spaces of this name")))))
  (cond ((find-duplicate (lab-ports lab))
         => (lambda (port)
              (lab-file-error path (list 'port port)
                              "two things on this port (address spaces at port-base + i, robots' trip servers at port-base + 100 + i)"))))
  (for-each (lambda (file)
              (if (not (file-exists? (lab-path lab file)))
                  (lab-file-error path (list 'code file) "no such file")))
            (lab-setting lab 'code)))

(define (find-duplicate ls)
  (let loop ((ls ls))
    (cond ((null? ls) #f)
          ((member (car ls) (cdr ls)) (car ls))
          (else (loop (cdr ls))))))

;; Every port the lab's address spaces and robots listen on.
(define (lab-ports lab)
  (append (map lab-aspace-port (lab-aspaces lab))
          (filter-map (lambda (a) (and (lab-aspace-clause a 'robot) (lab-trip-port lab a)))
                      (lab-aspaces lab))))

(define (condition-message e)
  (if (error-object? e) (error-object-message e) e))

(define (parse-aspace path form index base interface)
  (if (not (and (pair? (cdr form)) (symbol? (cadr form)) (list? (cddr form))))
      (error "an aspace clause is (aspace NAME CLAUSE ...)" path form))
  (let ((clauses (cddr form)))
    (make-lab-aspace (cadr form) index
                     (clause-value 'host clauses interface)
                     (clause-value 'port clauses (+ base index))
                     clauses)))

(define (path-directory path)
  (let loop ((i (- (string-length path) 1)))
    (cond ((< i 0) ".")
          ((char=? (string-ref path i) #\/)
           (if (zero? i) "/" (substring path 0 i)))
          (else (loop (- i 1))))))

;;> A path named in the lab file, which is relative to the file.
(define (lab-path lab file)
  (if (and (> (string-length file) 0) (char=? (string-ref file 0) #\/))
      file
      (string-append (lab-directory lab) "/" file)))

;;> The address space of the lab named \var{uid}, or #f.
(define (lab-aspace-by-uid lab uid)
  (find (lambda (a) (eq? (lab-aspace-uid a) uid)) (lab-aspaces lab)))

;;> The port of the trip server of robot \var{a}: its (robot (trip-port N))
;;> or port-base + 100 + its index.
(define (lab-trip-port lab a)
  (robot-setting a 'trip-port (+ (lab-port-base lab) 100 (lab-aspace-index a))))

;;> The host of the trip server of robot \var{a}: its (robot (trip-host
;;> "ADDR")), for a robot whose address space runs on another host than
;;> the simulator, or else its address space's host.
(define (lab-trip-host lab a)
  (robot-setting a 'trip-host (lab-aspace-host a)))

(define (robot-setting a key default)
  (let ((robot (lab-aspace-clause a 'robot)))
    (cond ((and robot (find (lambda (c) (and (pair? c) (eq? (car c) key) (pair? (cdr c))))
                            (cdr robot)))
           => cadr)
          (else default))))

;;> The uids of the lab's robots, in file order.
(define (lab-robots lab)
  (map lab-aspace-uid
       (filter (lambda (a) (lab-aspace-clause a 'robot)) (lab-aspaces lab))))

;;; The key

(define key-bytes 32)

;;> The lab's key as a bytevector, read from its key file.  When the file
;;> does not exist it is made: written under a temporary name with mode
;;> 0600 and linked into place, so that peers starting at once all end up
;;> with the one key that won, and none reads a half-written file.
(define (lab-key lab)
  (let ((file (lab-path lab (lab-setting lab 'key-file))))
    (if (not (file-exists? file))
        (make-key-file file))
    (let ((hex (call-with-input-file file read-line)))
      (if (or (eof-object? hex) (< (string-length hex) 32))
          (error "the lab's key file is too short" file))
      (string->utf8 hex))))

(define (make-key-file file)
  (let ((temp (string-append file "." (number->string (current-process-id))
                             ".new")))
    (let ((fd (open temp (bitwise-ior open/write open/create open/exclusive)
                    #o600)))
      (if (not fd) (error "cannot create the key file" temp))
      (let ((out (open-output-file-descriptor fd)))
        (write-string (random-hex key-bytes) out)
        (newline out)
        (close-output-port out)))
    (link-file temp file)               ; fails harmlessly if another won
    (delete-file temp)))

(define (random-hex n)
  (let ((bytes (call-with-port (open-binary-input-file "/dev/urandom")
                 (lambda (in) (read-bytevector n in)))))
    (apply string-append
           (map (lambda (b)
                  (string-append (if (< b 16) "0" "") (number->string b 16)))
                (bytevector->list bytes)))))

(define (bytevector->list bv)
  (let loop ((i (- (bytevector-length bv) 1)) (acc '()))
    (if (< i 0) acc (loop (- i 1) (cons (bytevector-u8-ref bv i) acc)))))
